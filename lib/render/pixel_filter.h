// Cycles' pixel filter (Film > Pixel Filter): where in and around its pixel a camera sample
// lands. Cycles importance-samples the filter, so every sample counts fully towards its own
// pixel: a wider filter softens edges and leaves flat regions alone.
//
// Cycles' table (scene/film.cpp filter_table, util/math_cdf.h util_cdf_inverted with
// make_symmetric, at v3.4.0, v4.5.0 and v5.0.0): the filter f on [0, R] is summed at 1023
// points into a CDF, inverted at 512 even steps and mirrored about the pixel centre into 1023
// of 1024 entries; the last entry stays 0. A uniform u picks a position by linear
// interpolation in the table (kernel lookup_table_read), separately along x and y. Box of
// width w: f = 1, R = w/2; Gaussian: f(x) = exp(−2(2x/w)²), R = 1.5w; Blackman-Harris:
// f(x) = 0.35875 − 0.48829 cos t + 0.14128 cos 2t − 0.01168 cos 3t with t = 2π(x/(2w) + 1/2),
// R = w.
#pragma once

#include <array>

#include "render/render_settings.h"

namespace hairis {

class PixelFilter {
  public:
    static constexpr int kTableSize = 1024;

    /// `width` in pixels, > 0.
    PixelFilter(PixelFilterType type, float width);

    /// The sample's position along one axis, in pixels from the pixel's low edge (the centre
    /// is 0.5), for u in [0, 1]. A box of width 1 gives u itself.
    float position(float u) const;

  private:
    bool identity_ = false;
    std::array<float, kTableSize> table_{};
};

}  // namespace hairis
