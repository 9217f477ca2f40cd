// What a study prints: every line goes to stdout at once, so that a long run shows its progress,
// and into the Markdown report that the study writes at the end.
#pragma once

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

namespace hairis::bench {

class Report {
  public:
    /// Prints like std::printf and keeps the text.
    void print(const char *format, ...) __attribute__((format(printf, 2, 3))) {
        va_list args, again;
        va_start(args, format);
        va_copy(again, args);
        const int n = std::vsnprintf(nullptr, 0, format, args);
        va_end(args);
        std::vector<char> buffer(std::size_t(n > 0 ? n : 0) + 1);
        std::vsnprintf(buffer.data(), buffer.size(), format, again);
        va_end(again);
        std::fputs(buffer.data(), stdout);
        std::fflush(stdout);
        text_ += buffer.data();
    }
    /// Everything printed so far.
    const std::string &str() const { return text_; }

  private:
    std::string text_;
};

/// A study's command line: a sample count (argv[1], default `fallback`) and the folder to write
/// its report into (argv[2], empty for none).
struct StudyArguments {
    long long samples = 0;
    std::string folder;
};

/// The study's arguments; nothing, after saying why on stderr, when the sample count is below
/// `minimum`.
inline std::optional<StudyArguments> study_arguments(int argc, char **argv, long long fallback,
                                                     long long minimum, const char *study) {
    StudyArguments a{argc > 1 ? std::atoll(argv[1]) : fallback, argc > 2 ? argv[2] : ""};
    if (a.samples >= minimum) return a;
    std::fprintf(stderr, "%s: samples must be at least %lld (got %s)\n", study, minimum,
                 argc > 1 ? argv[1] : "nothing");
    return std::nullopt;
}

}  // namespace hairis::bench
