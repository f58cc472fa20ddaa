// libFuzzer target: the model-file reader and the geometry it describes.
//
// Any input is a model file. The reader must either accept it or throw InputError
// (file, line, key); an accepted model is generated under a small limit on blocks
// and triangles, and must either give blocks or throw GeometryError. Anything else
// — another exception, a crash, a sanitizer report, a hang — is a bug. Build with
// -DBBM_FUZZ=ON and clang (tests/fuzz/README.md).
#include "io/model_input.hpp"
#include "base/error.hpp"
#include "meshing/blocks.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    bbm::io::ModelFile model;
    try {
        model = bbm::io::parse_model(text, "fuzz.toml");
    } catch (const bbm::InputError&) {
        return 0;
    }
    // Small models only: the fuzzer looks for wrong handling, not for big meshes.
    model.geometry.max_elements = 3000;
    try {
        (void)bbm::meshing::generate_blocks(model.geometry);
    } catch (const bbm::GeometryError&) {
    }
    return 0;
}
