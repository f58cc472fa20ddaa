// bbm io: the few binary read/write helpers of checkpoint files (native byte
// order: a checkpoint resumes on the machine kind that wrote it). Reads throw
// std::runtime_error naming what is wrong with the file.
#pragma once

#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>

namespace bbm::io {

template <class T>
void put(std::ostream& o, const T& v) {
    o.write(reinterpret_cast<const char*>(&v), sizeof v);
}

inline void put_string(std::ostream& o, const std::string& s) {
    put(o, std::uint64_t(s.size()));
    o.write(s.data(), std::streamsize(s.size()));
}

template <class T>
T get(std::istream& i) {
    T v{};
    i.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!i) throw std::runtime_error("checkpoint is truncated");
    return v;
}

/// A string written by put_string, at most `limit` bytes (a larger length means a corrupt file).
inline std::string get_string(std::istream& i, std::uint64_t limit = 1u << 20) {
    const auto n = get<std::uint64_t>(i);
    if (n > limit) throw std::runtime_error("checkpoint is corrupt");
    std::string s(n, '\0');
    i.read(s.data(), std::streamsize(n));
    if (!i) throw std::runtime_error("checkpoint is truncated");
    return s;
}

} // namespace bbm::io
