// A model built from the text of a model file, for tests that write their model
// inline (supports, dowels, water): the file read and its blocks generated.
#pragma once

#include "io/model_input.hpp"
#include "meshing/blocks.hpp"

#include <string>

namespace bbm::test {

struct BuiltModel {
    io::ModelFile file;
    meshing::BlockAssembly blocks;
};

/// `name` is the file name error messages give.
inline BuiltModel build_model(const std::string& text, const std::string& name) {
    BuiltModel b{io::parse_model(text, name), {}};
    b.blocks = meshing::generate_blocks(b.file.geometry);
    return b;
}

} // namespace bbm::test
