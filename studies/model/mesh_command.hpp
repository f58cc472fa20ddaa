// bbm studies: `bbm mesh` as a library call — generate a model file's blocks and
// write blocks.vtu, joints.vtu, blocks.png and summary.json (counts, areas, block
// sizes, the fracture network as built against what was asked).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace bbm::studies {

struct MeshCommand {
    std::string model;
    std::filesystem::path out = "out";
    std::vector<double> window; ///< XMIN YMIN XMAX YMAX of blocks.png, or empty
    double max_elements = 0;
};

/// Generates the blocks and writes the files in command.out (nothing when
/// check_only). Throws InputError naming the model file, line and key.
int run_mesh(const MeshCommand& command, bool quiet, bool check_only);

} // namespace bbm::studies
