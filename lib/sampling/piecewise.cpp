#include "sampling/piecewise.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace hairis {

namespace {

float next_up(float x) { return std::nextafter(x, std::numeric_limits<float>::infinity()); }
float next_down(float x) { return std::nextafter(x, -std::numeric_limits<float>::infinity()); }

// Float bit patterns mapped to unsigned integers in the order of the floats they encode
// (−0 just below +0), for bisection over floats.
std::uint32_t ordered_bits(float x) {
    std::uint32_t b;
    std::memcpy(&b, &x, sizeof b);
    return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}
float from_ordered_bits(std::uint32_t k) {
    const std::uint32_t b = (k & 0x80000000u) ? (k & 0x7fffffffu) : ~k;
    float x;
    std::memcpy(&x, &b, sizeof x);
    return x;
}

// The smallest power of two >= n (n >= 1).
int guide_size_for(int n) {
    int g = 1;
    while (g < n) g <<= 1;
    return g;
}

// Validates cell values: finite and non-negative, naming the first offender.
Status check_values(const char *what, const float *values, size_t count) {
    for (size_t i = 0; i < count; ++i) {
        if (!(std::isfinite(values[i]) && values[i] >= 0.0f)) {
            const std::string name = std::string(what) + "[" + std::to_string(i) + "]";
            return check::non_negative(name.c_str(), double(values[i]));
        }
    }
    return std::nullopt;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// UniformCells

Expected<UniformCells> UniformCells::create(float lo, float hi, int count) {
    if (Status s = first_error(check::finite("interval lower end", lo),
                               check::finite("interval upper end", hi),
                               check::count_in_range("cell count", count, 1, kMaxCells)))
        return *s;
    if (!(hi > lo))
        return Error{"interval [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "] must have upper end > lower end"};
    const double length = double(hi) - double(lo);
    if (!std::isfinite(float(length)))
        return Error{"interval [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "] is too long for float arithmetic"};

    UniformCells c;
    c.lo_ = lo;
    c.hi_ = hi;
    c.count_ = count;
    c.width_ = float(length / count);
    c.inv_width_ = float(count / length);
    c.edges_.resize(size_t(count) + 1);
    c.edges_[0] = lo;
    c.edges_[size_t(count)] = hi;
    // cell_of() is monotone in x (subtraction, multiplication by a positive constant and
    // truncation all preserve order), so each cell is an interval of floats. Its first float
    // is usually the exact boundary rounded to float or a neighbour; otherwise bisect over the
    // floats between the previous edge and hi (32 steps at most).
    for (int k = 1; k < count; ++k) {
        const float guess = float(double(lo) + length * k / count);
        float e = guess;
        if (!(guess > c.edges_[size_t(k) - 1] && guess <= hi && c.cell_of(guess) >= k &&
              c.cell_of(next_down(guess)) < k)) {
            std::uint32_t below = ordered_bits(c.edges_[size_t(k) - 1]), above = ordered_bits(hi);
            while (above - below > 1) {
                const std::uint32_t mid = below + (above - below) / 2;
                (c.cell_of(from_ordered_bits(mid)) < k ? below : above) = mid;
            }
            e = from_ordered_bits(above);
        }
        if (c.cell_of(e) != k || !(e > c.edges_[size_t(k) - 1]))
            return Error{"interval [" + std::to_string(lo) + ", " + std::to_string(hi) +
                         "] is too narrow for " + std::to_string(count) +
                         " cells in float precision"};
        c.edges_[size_t(k)] = e;
    }
    c.last_in_cell_.resize(size_t(count));
    for (int k = 0; k < count; ++k)
        c.last_in_cell_[size_t(k)] = k + 1 == count ? hi : next_down(c.edges_[size_t(k) + 1]);
    return c;
}

float UniformCells::fraction_in_cell(int k, float x) const {
    const float t = (x - edge(k)) / (edge(k + 1) - edge(k));
    return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

// ---------------------------------------------------------------------------------------------
// DiscreteCdfs

long long DiscreteCdfs::bytes_needed(long long count, long long size) {
    const long long guide = guide_size_for(int(std::min<long long>(size, kMaxSize)));
    const long long entry = size <= 65536 ? 2 : 4;
    return count * ((size + 1) * (long long)sizeof(float) + guide * entry + 1);
}

DiscreteCdfs::DiscreteCdfs(int count, int size)
    : count_(count),
      size_(size),
      guide_size_(guide_size_for(size)),
      narrow_(size <= 65536),
      cdf_(size_t(count) * size_t(size + 1), 0.0f),
      fallback_(size_t(count), 0) {
    if (narrow_)
        guide16_.resize(size_t(count) * size_t(guide_size_));
    else
        guide32_.resize(size_t(count) * size_t(guide_size_));
}

Status DiscreteCdfs::set_row(int row, const double *w) {
    const int n = size_;
    float *c = cdf_.data() + size_t(row) * size_t(n + 1);
    double total = 0.0;
    for (int k = 0; k < n; ++k) {
        if (!(std::isfinite(w[k]) && w[k] >= 0.0)) {
            const std::string name = "weight[" + std::to_string(k) + "]";
            return check::non_negative(name.c_str(), w[k]);
        }
        total += w[k];
    }
    if (!std::isfinite(total)) return Error{"weights sum to infinity"};

    if (total == 0.0) {
        // Nothing to sample: uniform over the cells, flagged.
        fallback_[size_t(row)] = 1;
        for (int k = 0; k <= n; ++k) c[k] = float(double(k) / n);
        c[n] = 1.0f;
    } else {
        // Forward: the CDF rounded to float, positive cells keeping at least one ulp, cells of
        // zero weight exactly flat.
        c[0] = 0.0f;
        double partial = 0.0;
        for (int k = 0; k < n; ++k) {
            partial += w[k];
            if (w[k] > 0.0)
                c[k + 1] = std::max(float(std::min(partial / total, 1.0)), next_up(c[k]));
            else
                c[k + 1] = c[k];
        }
        // Backward: end exactly at 1 and keep the forward invariants from that side.
        c[n] = 1.0f;
        for (int k = n - 1; k >= 0; --k)
            c[k] = w[k] > 0.0 ? std::min(c[k], next_down(c[k + 1])) : c[k + 1];
        bool ok = c[0] == 0.0f;
        for (int k = 0; k < n && ok; ++k) ok = w[k] > 0.0 ? c[k + 1] > c[k] : c[k + 1] == c[k];
        if (!ok)
            return Error{"too many cells of tiny mass to represent the CDF in float precision"};
    }

    // Guide: entry j is the last cell whose CDF start is <= j / G, the smallest u it serves.
    const size_t first = size_t(row) * size_t(guide_size_);
    int k = 0;
    for (int j = 0; j < guide_size_; ++j) {
        const float v = float(j) / float(guide_size_);  // exact
        while (k + 1 < n && c[k + 1] <= v) ++k;
        if (narrow_)
            guide16_[first + size_t(j)] = std::uint16_t(k);
        else
            guide32_[first + size_t(j)] = std::uint32_t(k);
    }
    return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// PiecewiseConstant1D

Expected<PiecewiseConstant1D> PiecewiseConstant1D::create(const std::vector<float> &values,
                                                          float lo, float hi) {
    if (values.size() > size_t(UniformCells::kMaxCells))
        return check::count_in_range("cell count", (long long)values.size(), 1,
                                     UniformCells::kMaxCells)
            .value();
    return create(values.data(), int(values.size()), lo, hi);
}

Expected<PiecewiseConstant1D> PiecewiseConstant1D::create(const float *values, int count, float lo,
                                                          float hi) {
    Expected<UniformCells> cells = UniformCells::create(lo, hi, count);
    if (!cells) return cells.error();
    if (values == nullptr) return Error{"values must not be null"};
    if (Status s = check_values("values", values, size_t(count))) return *s;

    Expected<DiscreteCdfs> cdfs = DiscreteCdfs::create(1, count, [&](int, double *w) {
        for (int k = 0; k < count; ++k) w[k] = values[k];
    });
    if (!cdfs) return cdfs.error();
    double sum = 0.0;
    for (int k = 0; k < count; ++k) sum += values[k];
    const double integral = sum * ((double(hi) - double(lo)) / count);
    return PiecewiseConstant1D(std::move(cells).value(), std::move(cdfs).value(),
                               std::vector<float>(values, values + count), integral);
}

float PiecewiseConstant1D::invert(float x) const {
    if (!(x >= cells_.lo())) return 0.0f;  // also NaN
    if (x >= cells_.hi()) return 1.0f;
    const int k = cells_.cell_of(x);
    return cdfs_.invert(0, k, cells_.fraction_in_cell(k, x));
}

// ---------------------------------------------------------------------------------------------
// PiecewiseConstant2D

PiecewiseConstant2D::PiecewiseConstant2D(UniformCells xs, UniformCells ys, DiscreteCdfs marginal,
                                         DiscreteCdfs conditional, std::vector<float> values)
    : xs_(std::move(xs)),
      ys_(std::move(ys)),
      marginal_(std::move(marginal)),
      conditional_(std::move(conditional)),
      values_(std::move(values)) {
    inv_cell_area_ = float(double(xs_.inv_width()) * double(ys_.inv_width()));
}

Expected<PiecewiseConstant2D> PiecewiseConstant2D::create(const std::vector<float> &values,
                                                          int rows, int cols, float x_lo,
                                                          float x_hi, float y_lo, float y_hi) {
    if (Status s =
            first_error(check::count_in_range("row count", rows, 1, UniformCells::kMaxCells),
                        check::count_in_range("column count", cols, 1, UniformCells::kMaxCells)))
        return *s;
    const long long cells = (long long)rows * cols;
    if (cells > UniformCells::kMaxCells)
        return Error{"rows × columns = " + std::to_string(cells) + " exceeds the limit of " +
                     std::to_string(UniformCells::kMaxCells) + " cells"};
    if ((long long)values.size() != cells)
        return Error{"values must hold rows × columns = " + std::to_string(cells) +
                     " entries (got " + std::to_string(values.size()) + ")"};
    Expected<UniformCells> xs = UniformCells::create(x_lo, x_hi, rows);
    if (!xs) return Error{"x axis: " + xs.error().message};
    Expected<UniformCells> ys = UniformCells::create(y_lo, y_hi, cols);
    if (!ys) return Error{"y axis: " + ys.error().message};
    if (Status s = check_values("values", values.data(), values.size())) return *s;

    Expected<DiscreteCdfs> conditional = DiscreteCdfs::create(rows, cols, [&](int r, double *w) {
        for (int c = 0; c < cols; ++c) w[c] = values[size_t(r) * size_t(cols) + size_t(c)];
    });
    if (!conditional) return conditional.error();
    // Cells have equal areas, so a row's mass is proportional to the sum of its values.
    Expected<DiscreteCdfs> marginal = DiscreteCdfs::create(1, rows, [&](int, double *w) {
        for (int r = 0; r < rows; ++r) {
            double sum = 0.0;
            for (int c = 0; c < cols; ++c) sum += values[size_t(r) * size_t(cols) + size_t(c)];
            w[r] = sum;
        }
    });
    if (!marginal) return marginal.error();
    return PiecewiseConstant2D(std::move(xs).value(), std::move(ys).value(),
                               std::move(marginal).value(), std::move(conditional).value(), values);
}

Point2 PiecewiseConstant2D::invert(float x, float y) const {
    x = std::clamp(std::isnan(x) ? xs_.lo() : x, xs_.lo(), xs_.hi());
    y = std::clamp(std::isnan(y) ? ys_.lo() : y, ys_.lo(), ys_.hi());
    const int r = xs_.cell_of(x), c = ys_.cell_of(y);
    return {marginal_.invert(0, r, xs_.fraction_in_cell(r, x)),
            conditional_.invert(r, c, ys_.fraction_in_cell(c, y))};
}

}  // namespace hairis
