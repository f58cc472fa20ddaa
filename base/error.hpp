// bbm base: the error types that carry the user back to what must be fixed.
//
// InputError is the one always-on check for anything a user wrote: it names the
// file, the line and the key (e.g. "tunnel.toml:12: region[1].pattern.size: must
// be > 0, got -0.3"). GeometryError is raised by the geometry layer, which knows
// nothing of files: it names the region (by index) and the key of the offending
// shape, and the input layer turns it into an InputError with the right line.
// Internal invariants use BBM_ASSERT, active in Debug and in the heavy-validation
// build (BBM_VALIDATE), compiled out otherwise.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

namespace bbm {

class InputError : public std::runtime_error {
public:
    InputError(std::string file, int line, std::string key, std::string message)
        : std::runtime_error(format(file, line, key, message)), file_(std::move(file)),
          line_(line), key_(std::move(key)), message_(std::move(message)) {}
    const std::string& file() const { return file_; }
    int line() const { return line_; }
    const std::string& key() const { return key_; }
    /// The message alone, without file, line and key.
    const std::string& message() const { return message_; }

private:
    static std::string format(const std::string& file, int line, const std::string& key,
                              const std::string& message) {
        std::ostringstream s;
        s << file;
        if (line > 0) s << ':' << line;
        s << ": ";
        if (!key.empty()) s << key << ": ";
        s << message;
        return s.str();
    }
    std::string file_;
    int line_;
    std::string key_;
    std::string message_;
};

/// A numerical failure whose cause is known (a load beyond what the stiffnesses
/// carry, a collapsing time step): the programs exit with status 3 and keep the
/// output written so far, marked incomplete.
class NumericalError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A study stopped by SIGINT, SIGTERM or SIGUSR1 (a lab test, calibration, envelope,
/// shear test, or a sweep's run not yet started): bbm exits with status 130 and
/// writes nothing for it (`bbm run` checkpoints instead and returns 130 itself).
class Interrupted : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The implicit elastic system has no unique solution: a block, node or group can
/// move without resistance (no joints or broken ones, no support). A caller that
/// has another way on (a lab test loading explicitly) catches this type alone.
class SingularSystemError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A geometric defect in one region's description (self-intersection, hole outside,
/// overlap). `region` indexes the region list; `key` is the key inside that region.
class GeometryError : public std::runtime_error {
public:
    GeometryError(int region, std::string key, const std::string& message)
        : std::runtime_error(message), region_(region), key_(std::move(key)) {}
    int region() const { return region_; }
    const std::string& key() const { return key_; }

private:
    int region_;
    std::string key_;
};

} // namespace bbm

#if !defined(NDEBUG) || defined(BBM_VALIDATE)
#define BBM_ASSERT(cond, msg)                                                                      \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            std::fprintf(stderr, "%s:%d: internal check failed: %s (%s)\n", __FILE__, __LINE__,   \
                         #cond, msg);                                                              \
            std::abort();                                                                          \
        }                                                                                          \
    } while (0)
#else
#define BBM_ASSERT(cond, msg) ((void)0)
#endif
