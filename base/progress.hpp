// bbm base: progress lines that suit their reader.
//
// On a terminal a progress line is rewritten in place about once a second (a
// carriage return before it), and a result line (a stage's or a test's end)
// replaces it. When standard error is not a terminal — a log file, a pipe, a batch
// system's output — every line is a line of its own and progress comes every
// BBM_PROGRESS_SECONDS seconds (default 10), never with a carriage return: so
// `bbm compare ... 2>&1 | tail` and a Slurm log read line by line.
#pragma once

#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

namespace bbm {

class Progress {
public:
    Progress() : terminal_(isatty(fileno(stderr)) != 0), interval_(terminal_ ? 1.0 : 10.0) {
        if (const char* v = std::getenv("BBM_PROGRESS_SECONDS")) {
            char* end = nullptr;
            const double s = std::strtod(v, &end);
            if (end != v && s >= 0.0) interval_ = s;
        }
    }
    /// Whether a progress line is due now (one interval since the last, or since
    /// the start); if so, the interval starts again.
    bool due() {
        const auto now = std::chrono::steady_clock::now();
        if (std::chrono::duration<double>(now - last_).count() < interval_) return false;
        last_ = now;
        return true;
    }
    /// A progress line (no newline in `fmt`): over the last one on a terminal.
    __attribute__((format(printf, 2, 3))) void line(const char* fmt, ...) {
        va_list ap;
        va_start(ap, fmt);
        emit(true, fmt, ap);
        va_end(ap);
    }
    /// A line that stays (no newline in `fmt`): on a terminal it replaces the
    /// progress line.
    __attribute__((format(printf, 2, 3))) void result(const char* fmt, ...) {
        va_list ap;
        va_start(ap, fmt);
        emit(false, fmt, ap);
        va_end(ap);
    }

private:
    void emit(bool progress, const char* fmt, va_list ap) {
        char buffer[2048];
        std::vsnprintf(buffer, sizeof buffer, fmt, ap);
        const std::string text(buffer);
        if (terminal_) {
            const std::size_t pad = shown_ > text.size() ? shown_ - text.size() : 0;
            std::fprintf(stderr, "\r%s%s%s", text.c_str(), std::string(pad, ' ').c_str(), progress ? "" : "\n");
            shown_ = progress ? text.size() : 0;
        } else {
            std::fprintf(stderr, "%s\n", text.c_str());
        }
        std::fflush(stderr);
    }

    bool terminal_;
    double interval_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
    std::size_t shown_ = 0; ///< length of the progress line on the terminal
};

} // namespace bbm
