// libFuzzer target: the DXF reader of fracture traces (io/dxf.hpp).
//
// Any input is a DXF file. The reader must either return traces with finite
// coordinates or throw InputError (file, line, key); anything else — another
// exception, a crash, a sanitizer report, a hang — is a bug.
#include "base/error.hpp"
#include "io/dxf.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/bbm_fuzz_dxf_" + std::to_string(::getpid()) + ".dxf";
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(data), std::streamsize(size));
    try {
        const auto d = bbm::io::read_dxf(path, "dfn[0].file");
        for (const auto& t : d.traces)
            if (!std::isfinite(t.a.x + t.a.y + t.b.x + t.b.y)) std::abort();
    } catch (const bbm::InputError&) {
    }
    return 0;
}
