#include "npy.h"

#include <fstream>

namespace hairis::cli {

Status write_npy(const std::string &path, const std::vector<float> &values, const std::vector<size_t> &shape) {
    size_t count = 1;
    std::string dims;
    for (size_t d : shape) {
        count *= d;
        dims += std::to_string(d) + ", ";
    }
    if (count != values.size()) return Error{"write_npy: shape does not match the data (a bug)"};
    if (shape.size() > 1) dims.erase(dims.size() - 2);  // "(a, b)"; a 1-tuple keeps "(a, )"
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + dims + "), }";
    // Magic (6) + version (2) + length (2) + header, padded with spaces to a multiple of 64.
    const size_t unpadded = 10 + header.size() + 1;
    header.append((64 - unpadded % 64) % 64, ' ');
    header += '\n';
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) return Error{"cannot write \"" + path + "\""};
    const unsigned short len = (unsigned short)header.size();
    out.write("\x93NUMPY\x01\x00", 8);
    out.put(char(len & 0xff));
    out.put(char(len >> 8));
    out.write(header.data(), std::streamsize(header.size()));
    out.write(reinterpret_cast<const char *>(values.data()), std::streamsize(values.size() * sizeof(float)));
    if (!out) return Error{"writing \"" + path + "\" failed"};
    return std::nullopt;
}

}  // namespace hairis::cli
