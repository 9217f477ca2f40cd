// What the seed writers share: their command line, `write_<target>_seeds DIR`, and writing
// each seed as a file of that folder.
#pragma once

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace hairis::fuzz {

/// Seeds by file name.
using Seeds = std::vector<std::pair<std::string, std::vector<unsigned char>>>;

/// The folder that the command line names, or nothing after printing the usage.
inline const char *seed_folder(int argc, char **argv) {
    if (argc == 2) return argv[1];
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return nullptr;
}

/// Writes each seed as folder/name and returns main's exit status: 0, or 1 after naming the
/// file that could not be written.
inline int write_seeds(const char *folder, const Seeds &seeds) {
    for (const auto &[name, bytes] : seeds) {
        const std::string path = std::string(folder) + "/" + name;
        std::FILE *f = std::fopen(path.c_str(), "wb");
        const bool written = f && std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
        if (f && std::fclose(f) != 0) f = nullptr;
        if (!written || !f) {
            std::fprintf(stderr, "cannot write %s\n", path.c_str());
            return 1;
        }
    }
    std::printf("wrote %zu seeds to %s\n", seeds.size(), folder);
    return 0;
}

}  // namespace hairis::fuzz
