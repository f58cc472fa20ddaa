// libFuzzer target: `bbm --config FILE COMMAND --check`, the options of a lab test
// or calibration read from a TOML file.
//
// The first byte picks the command, the rest is the file. The program must end
// with status 0 (valid) or 2 (a mistake it names); it is the program's command line
// (apps/cli.cpp: bbm_cli_main, the same object as bbm's), so every check the
// command line has is the one fuzzed. --check stops before any work.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

int bbm_cli_main(int argc, char** argv);

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* commands[] = {"ucs", "tension", "biaxial", "brazilian", "calibrate"};
    const char* command = commands[data[0] % 5];
    static const std::string path = "/tmp/bbm-fuzz-config-" + std::to_string(getpid()) + ".toml";
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
    std::string args[] = {"bbm", "--check", "--quiet", "--config", path, command};
    char* argv[6];
    for (int i = 0; i < 6; ++i) argv[i] = args[i].data();
    const int status = bbm_cli_main(6, argv);
    if (status != 0 && status != 2) {
        std::fprintf(stderr, "bbm %s --config: exit status %d, expected 0 or 2\n", command, status);
        std::abort();
    }
    return 0;
}
