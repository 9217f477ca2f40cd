// C API: sampling tables — bake, write, load (file or memory), metadata and fiber matching.
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "capi_internal.h"
#include "tables/bake.h"

namespace hairis::capi {

namespace {

hairis_tables *make_tables(TableSet set) {
    Expected<SamplingTables> sampling = SamplingTables::from(set);
    if (!sampling) refuse(HAIRIS_ERROR_INVALID_TABLE, "hairis table: " + sampling.error().message);
    auto tables = std::make_unique<hairis_tables>();
    tables->parameters = canonical_parameters(set.parameters);
    std::string n_h;
    for (int v : set.n_h_values) n_h += (n_h.empty() ? "" : ",") + std::to_string(v);
    if (const HuangTableSet *h = set.huang.get()) {
        std::vector<std::pair<std::string, std::string>> info = {
            {"source", set.source},
            {"huang_theta_o", std::to_string(h->theta_o_count())},
            {"huang_phi_o", std::to_string(h->phi_o_count())},
            {"huang_theta_i", std::to_string(h->theta_i_count)},
            {"huang_phi", std::to_string(h->phi_count)},
            {"huang_f", h->has_f() ? "1" : "0"}};
        if (h->has_f()) info.push_back({"huang_f_refinement", std::to_string(h->f_refinement)});
        info.push_back({"huang_absorption", h->has_absorption() ? "1" : "0"});
        if (h->has_absorption()) info.push_back({"huang_absorption_nodes", std::to_string(h->absorption_count())});
        if (set.has_multiple()) {  // the multiple part (dual scattering)
            info.push_back({"theta_r", std::to_string(set.theta_r_count())});
            info.push_back({"theta_i", std::to_string(set.theta_i_count)});
            info.push_back({"n_h", n_h});
        }
        tables->info = format_options(info);
        tables->sampling = std::move(sampling).value();
        tables->set = std::move(set);
        return tables.release();
    }
    tables->info = format_options({{"source", set.source},
                                   {"theta_r", std::to_string(set.theta_r_count())},
                                   {"theta_i", std::to_string(set.theta_i_count)},
                                   {"phi", std::to_string(set.phi_count)},
                                   {"n_h", n_h}});
    tables->sampling = std::move(sampling).value();
    tables->set = std::move(set);
    return tables.release();
}

// Decoded table files by a fingerprint of their bytes: a renderer that loads the same file for
// every render (the add-on does) decodes and validates it once. A changed byte is a new key, so
// a damaged file is decoded, and refused, like any other.
class DecodedCache {
  public:
    hairis_tables *load(const void *data, size_t size, const std::string &where) {
        const std::string key = std::to_string(size) + ":" + table_file_fingerprint(data, size);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            for (auto it = entries_.begin(); it != entries_.end(); ++it)
                if (it->first == key) {
                    entries_.splice(entries_.begin(), entries_, it);  // most recent first
                    return new hairis_tables(*it->second);
                }
        }
        Expected<TableSet> set = decode_table_exr(data, size);
        if (!set) refuse(HAIRIS_ERROR_INVALID_TABLE, set.error().message + " (in " + where + ")");
        std::unique_ptr<hairis_tables> made(make_tables(std::move(set).value()));
        auto shared = std::make_shared<const hairis_tables>(*made);
        std::lock_guard<std::mutex> lock(mutex_);
        entries_.emplace_front(key, std::move(shared));
        if (entries_.size() > kEntries) entries_.pop_back();
        return made.release();
    }

  private:
    static constexpr size_t kEntries = 8;
    std::mutex mutex_;
    std::list<std::pair<std::string, std::shared_ptr<const hairis_tables>>> entries_;
};

DecodedCache &decoded_cache() {
    static DecodedCache cache;
    return cache;
}

// Reads a whole file; the error names the file and the system's reason.
std::vector<unsigned char> read_file(const std::string &path) {
    std::FILE *file = std::fopen(path.c_str(), "rb");
    if (!file)
        refuse(HAIRIS_ERROR_IO, "cannot open \"" + path + "\" for reading: " + std::strerror(errno));
    std::vector<unsigned char> bytes;
    unsigned char chunk[1 << 16];
    size_t got = 0;
    try {
        // Reserving the file's size saves the copies of a growing buffer; the loop still reads
        // to the end, so a file that changes size meanwhile is read whole.
        std::error_code ignored;
        const std::uintmax_t expected = std::filesystem::file_size(path, ignored);
        if (!ignored && expected < (std::uintmax_t(1) << 32)) bytes.reserve(size_t(expected));
        while ((got = std::fread(chunk, 1, sizeof chunk, file)) > 0)
            bytes.insert(bytes.end(), chunk, chunk + got);
    } catch (...) {
        std::fclose(file);
        throw;
    }
    const bool failed = std::ferror(file) != 0;
    std::fclose(file);
    if (failed) refuse(HAIRIS_ERROR_IO, "cannot read \"" + path + "\" (read error)");
    return bytes;
}

}  // namespace

}  // namespace hairis::capi

using namespace hairis;
using namespace hairis::capi;

extern "C" {

HAIRIS_API hairis_tables *hairis_tables_bake(const hairis_fiber *fiber, const char *options,
                                             hairis_progress_fn progress, void *user) {
    return guard_handle<hairis_tables>("hairis_tables_bake", [&] {
        require(fiber, "fiber");
        BakeOptions o;
        read_options(options, "bake options", o);
        ok_or_invalid(o.validate(), "bake options: ");

        Expected<std::vector<std::pair<std::string, double>>> parameters = fiber->spec.parameters();
        if (!parameters) invalid("fiber: " + parameters.error().message);

        bool cancelled = false;
        ProgressFn report;
        if (progress)
            report = [&](float fraction) {
                if (progress(user, fraction) != 0) cancelled = true;
                return !cancelled;
            };
        Expected<TableSet> baked = bake_tables(*fiber->model, parameters.value(), o, report);
        if (cancelled) refuse(HAIRIS_ERROR_CANCELLED, "cancelled");
        if (!baked) refuse(HAIRIS_ERROR_INTERNAL, "bake failed: " + baked.error().message);
        return make_tables(std::move(baked).value());
    });
}

HAIRIS_API int hairis_tables_write(const hairis_tables *tables, const char *path) {
    return guard_status("hairis_tables_write", [&] {
        require(tables, "tables");
        require(path, "path");
        if (*path == '\0') invalid("path must not be empty");
        if (Status s = write_table_file(tables->set, path)) refuse(HAIRIS_ERROR_IO, s->message);
        return HAIRIS_OK;
    });
}

HAIRIS_API hairis_tables *hairis_tables_load_file(const char *path) {
    return guard_handle<hairis_tables>("hairis_tables_load_file", [&] {
        require(path, "path");
        if (*path == '\0') invalid("path must not be empty");
        const std::vector<unsigned char> bytes = read_file(path);
        return decoded_cache().load(bytes.data(), bytes.size(), "\"" + std::string(path) + "\"");
    });
}

HAIRIS_API hairis_tables *hairis_tables_load_memory(const void *data, size_t size) {
    return guard_handle<hairis_tables>("hairis_tables_load_memory", [&] {
        require(data, "data");
        if (size == 0) invalid("size must be > 0 (an empty buffer is not a table file)");
        return decoded_cache().load(data, size, "the buffer");
    });
}

HAIRIS_API void hairis_tables_destroy(hairis_tables *tables) {
    guard_void("hairis_tables_destroy", [&] { delete tables; });
}

HAIRIS_API const char *hairis_tables_model(const hairis_tables *tables) {
    return guard_value<const char *>("hairis_tables_model", "", [&] {
        require(tables, "tables");
        return tables->set.model.c_str();
    });
}

HAIRIS_API const char *hairis_tables_parameters(const hairis_tables *tables) {
    return guard_value<const char *>("hairis_tables_parameters", "", [&] {
        require(tables, "tables");
        return tables->parameters.c_str();
    });
}

HAIRIS_API const char *hairis_tables_info(const hairis_tables *tables) {
    return guard_value<const char *>("hairis_tables_info", "", [&] {
        require(tables, "tables");
        return tables->info.c_str();
    });
}

HAIRIS_API int hairis_tables_match_fiber(const hairis_tables *tables, const hairis_fiber *fiber) {
    return guard_value<int>("hairis_tables_match_fiber", 0, [&] {
        require(tables, "tables");
        require(fiber, "fiber");
        return tables->set.model == fiber->model_name && tables->parameters == fiber->parameters
                   ? 1
                   : 0;
    });
}

}  // extern "C"
