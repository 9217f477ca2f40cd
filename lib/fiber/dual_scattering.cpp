#include "fiber/dual_scattering.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/frame.h"

namespace hairis {

namespace {

// Ā_b = ā_b x c/(1 − x) + ā_b³ x c³/(1 − x)³ with x = ā_f² (Zinke et al.'s eqs. for one and three
// backward scatterings); c = 1 − x^depth cuts both forward series at `depth` strands, c = 1 is
// the paper's unbounded volume.
double series_backscatter(double af, double ab, double cut) {
    const double x = af * af, om = 1.0 - x, c3 = cut * cut * cut;
    return ab * x * cut / om + ab * ab * ab * x * c3 / (om * om * om);
}

/// Normalised Gaussian g(x; variance).
double gaussian(double x, double variance) {
    return std::exp(-0.5 * x * x / variance) / std::sqrt(kTwoPi * variance);
}

Vec3 dir(double theta, double phi) { return direction_of(float(theta), float(phi)); }

/// Azimuths at which an eccentric fiber is averaged; one azimuth (Cycles' φ_o = −π/2) when the
/// model only depends on the relative azimuth.
std::vector<double> orientations(const FiberModel &model, int count) {
    if (model.rotationally_symmetric()) return {-kHalfPi};
    std::vector<double> out(static_cast<std::size_t>(count));
    for (int j = 0; j < count; ++j) out[std::size_t(j)] = -kPi + (j + 0.5) * kTwoPi / count;
    return out;
}

}  // namespace

// ------------------------------------------------------------------------------------------
// Precomputation

// The rules every step of the precomputation integrates with.
struct DualScattering::Quadrature {
    QuadratureRule theta;     // θ over [−π/2, π/2]
    QuadratureRule forward;   // φ over the forward half, [−π, −π/2] ∪ [π/2, π]
    QuadratureRule backward;  // φ over the backward half, [−π/2, π/2]
    std::vector<double> orientations;  // the azimuths an eccentric fiber is averaged over
    double weight_scale = 0;           // energy_scale / orientation count

    Quadrature(const FiberModel &model, const DualScatteringParams &q)
        : theta(QuadratureRule::composite(-kHalfPi, kHalfPi, q.theta_panels, q.points_per_panel)),
          forward(QuadratureRule::composite(-kPi, -kHalfPi, q.phi_panels, q.points_per_panel)),
          backward(QuadratureRule::composite(-kHalfPi, kHalfPi, 2 * q.phi_panels, q.points_per_panel)),
          orientations(hairis::orientations(model, q.orientation_count)),
          weight_scale(double(q.energy_scale) / double(orientations.size())) {
        const QuadratureRule upper = QuadratureRule::composite(kHalfPi, kPi, q.phi_panels, q.points_per_panel);
        forward.x.insert(forward.x.end(), upper.x.begin(), upper.x.end());
        forward.w.insert(forward.w.end(), upper.w.begin(), upper.w.end());
    }
};

Expected<DualScattering> DualScattering::create(const FiberModel &model,
                                                const DualScatteringParams &params) {
    const DualScatteringParams &q = params;
    if (Status s = first_error(
            check::in_range("DualScatteringParams::d_f", q.d_f, 0.0, 1.0),
            check::in_range("DualScatteringParams::d_b", q.d_b, 0.0, 1.0),
            check::count_in_range("DualScatteringParams::n_h", q.n_h, 0, 1 << 20),
            check::count_in_range("DualScatteringParams::theta_count", q.theta_count, 2, 4096),
            check::count_in_range("DualScatteringParams::theta_panels", q.theta_panels, 1, 1024),
            check::count_in_range("DualScatteringParams::phi_panels", q.phi_panels, 1, 1024),
            check::count_in_range("DualScatteringParams::points_per_panel", q.points_per_panel, 1, 16),
            check::count_in_range("DualScatteringParams::orientation_count", q.orientation_count, 1, 256),
            check::in_range("DualScatteringParams::max_series_attenuation", q.max_series_attenuation, 0.5, 0.9999),
            check::in_range("DualScatteringParams::min_lobe_width", q.min_lobe_width, 1e-6, 0.1),
            check::greater_than("DualScatteringParams::energy_scale", q.energy_scale, 0.0),
            check::in_range("DualScatteringParams::energy_scale", q.energy_scale, 0.0, 1.0)))
        return *s;
    const int lobes = model.lobe_count();
    if (Status s = check::count_in_range("FiberModel::lobe_count()", lobes, 1, 16)) return *s;

    DualScattering ds;
    ds.params_ = params;
    ds.lobe_count_ = lobes;
    for (int p = 0; p < lobes; ++p) {
        const LobeShape shape = model.lobe_shape(p);
        if (Status s = first_error(check::finite("FiberModel::lobe_shape().alpha", shape.alpha),
                                   check::non_negative("FiberModel::lobe_shape().beta", shape.beta)))
            return *s;
        ds.shapes_.push_back(shape);
    }

    const Quadrature rules(model, q);
    ds.integrate_albedos(model, rules);
    ds.integrate_spread(model, rules);
    ds.derive_terms();
    return ds;
}

namespace {

// θ_h moments of a lobe's energy: Σw, Σwθ_h, Σwθ_h².
struct LobeMoments {
    double m0 = 0, m1 = 0, m2 = 0;
    void add(double w, double theta_h) {
        m0 += w;
        m1 += w * theta_h;
        m2 += w * theta_h * theta_h;
    }
};

}  // namespace

// One θ node's integrals over the views of the light from θ_k: per lobe, the forward and
// backward albedos and, when the shapes are measured, the θ_h moments of the lobe's energy.
struct DualScattering::ViewAlbedos {
    const Quadrature &rules;
    double theta_k;
    bool measure;
    std::vector<Rgbd> af, ab;
    std::vector<LobeMoments> moments;
    std::vector<double> lw;  // a separable lobe's θ weights

    ViewAlbedos(const Quadrature &r, int lobes, double theta, bool measure_shapes)
        : rules(r), theta_k(theta), measure(measure_shapes), af(std::size_t(lobes)), ab(std::size_t(lobes)),
          moments(std::size_t(lobes)), lw(r.theta.x.size()) {}

    // The integrand factors per lobe: ∫ M_p cos θ dθ × ∫ N̄_p dφ over each half.
    void add_separable(const FarFieldView &view, double lobe_scale) {
        for (std::size_t p = 0; p < af.size(); ++p) {
            double longitudinal = 0;
            for (std::size_t m = 0; m < rules.theta.x.size(); ++m) {
                lw[m] = rules.theta.w[m] * std::cos(rules.theta.x[m]) * lobe_scale *
                        view.longitudinal(int(p), rules.theta.x[m]);
                longitudinal += lw[m];
            }
            double azimuthal_sum = 0;
            for (int half = 0; half < 2; ++half) {
                const QuadratureRule &rule = half == 0 ? rules.forward : rules.backward;
                Rgbd &acc = (half == 0 ? af : ab)[p];
                for (std::size_t n = 0; n < rule.x.size(); ++n) {
                    const Rgb v = view.azimuthal(int(p), rule.x[n]);
                    for (int ch = 0; ch < 3; ++ch) acc.v[ch] += longitudinal * rule.w[n] * double(v[ch]);
                    azimuthal_sum += rule.w[n] * (double(v[0]) + double(v[1]) + double(v[2]));
                }
            }
            if (measure)
                for (std::size_t m = 0; m < rules.theta.x.size(); ++m)
                    moments[p].add(lw[m] * azimuthal_sum, 0.5 * (rules.theta.x[m] + theta_k));
        }
    }

    // Any other view: f at every node of the product rule, the view's azimuth at φ_l.
    void add_sampled(const FarFieldView &view, double phi_l, double lobe_scale) {
        for (std::size_t m = 0; m < rules.theta.x.size(); ++m) {
            const double th = rules.theta.x[m];
            const double wm = rules.theta.w[m] * std::cos(th) * lobe_scale;
            const double theta_h = 0.5 * (th + theta_k);
            for (int half = 0; half < 2; ++half) {
                const QuadratureRule &rule = half == 0 ? rules.forward : rules.backward;
                std::vector<Rgbd> &acc = half == 0 ? af : ab;
                for (std::size_t n = 0; n < rule.x.size(); ++n) {
                    const Vec3 w = dir(th, phi_l + rule.x[n]);
                    const double weight = wm * rule.w[n];
                    for (std::size_t p = 0; p < af.size(); ++p) {
                        const Rgb v = view.lobe_f_cos(int(p), w);
                        for (int ch = 0; ch < 3; ++ch) acc[p].v[ch] += weight * double(v[ch]);
                        if (measure) moments[p].add(weight * (double(v[0]) + double(v[1]) + double(v[2])), theta_h);
                    }
                }
            }
        }
    }
};

// (1) Per lobe and θ node, the forward and backward albedos a_f,p and a_b,p and the share of a
// crossing that passes unscattered; and the lobes' shapes measured from the same integrals
// when the model's are not analytic (or DualScatteringParams::measure_lobe_shapes).
void DualScattering::integrate_albedos(const FiberModel &model, const Quadrature &rules) {
    const int K = params_.theta_count;
    const std::size_t nk = std::size_t(K);
    const std::size_t nl = std::size_t(lobe_count_);
    a_f_lobe_.assign(nl * nk, {});
    a_b_lobe_.assign(nl * nk, {});
    pass_.assign(nk, 0.0);
    shapes_measured_ = params_.measure_lobe_shapes || !model.lobe_shapes_analytic();
    std::vector<LobeMoments> moments(nl * nk);  // lobe p, θ node k at p * nk + k

    // Each task writes only its own table entries: the result does not depend on scheduling.
    tbb::parallel_for(tbb::blocked_range<int>(0, K), [&](const tbb::blocked_range<int> &range) {
        for (int k = range.begin(); k != range.end(); ++k) {
            // a_f,p and a_b,p at light inclination θ_L = θ_k. By reciprocity the fraction of the
            // light from ω_L scattered into the forward half is the model's white-furnace
            // integral ∫_fwd f(ω, ω_L)|cos θ| dω with ω_L in the viewer's slot: lobe_f_cos(p, ω,
            // ω_L) integrated against dω = cos θ dθ dφ.
            ViewAlbedos sums(rules, lobe_count_, table_theta(k), shapes_measured_);
            double pass = 0;  // the unscattered share of the light's crossings (projected_width)
            for (const double phi_l : rules.orientations) {
                const Vec3 light = dir(sums.theta_k, phi_l);
                const std::unique_ptr<const FarFieldView> view = model.view(light);
                // f is per hit on the fiber; a crossing meets it on a fraction `width` of the
                // curve's width and passes unscattered elsewhere.
                const double width = std::clamp(model.projected_width(light), 0.0, 1.0);
                pass += (1.0 - width) / double(rules.orientations.size());
                if (view->separable())
                    sums.add_separable(*view, rules.weight_scale * width);
                else
                    sums.add_sampled(*view, phi_l, rules.weight_scale * width);
            }
            for (std::size_t p = 0; p < nl; ++p) {
                a_f_lobe_[p * nk + std::size_t(k)] = sums.af[p];
                a_b_lobe_[p * nk + std::size_t(k)] = sums.ab[p];
                moments[p * nk + std::size_t(k)] = sums.moments[p];
            }
            pass_[std::size_t(k)] = pass;
        }
    });

    // Measured shapes: the moments pooled over θ_L with weight cos θ_L (serial, fixed order).
    if (!shapes_measured_) return;
    for (std::size_t p = 0; p < nl; ++p) {
        LobeMoments pooled;
        for (std::size_t k = 0; k < nk; ++k) {
            const LobeMoments &m = moments[p * nk + k];
            const double c = std::cos(table_theta(int(k)));
            pooled.m0 += c * m.m0;
            pooled.m1 += c * m.m1;
            pooled.m2 += c * m.m2;
        }
        if (!(pooled.m0 > 0)) continue;  // a lobe with no energy keeps the model's guess
        const double alpha = pooled.m1 / pooled.m0;
        const double variance = std::max(0.0, pooled.m2 / pooled.m0 - alpha * alpha);
        shapes_[p] = {float(alpha), float(std::sqrt(variance))};
    }
}

// (2) Per lobe and θ node, N_p^G: the lobe's forward azimuthal spread at Marschner's
// difference angle θ_d = θ_k.
void DualScattering::integrate_spread(const FiberModel &model, const Quadrature &rules) {
    const int K = params_.theta_count;
    const std::size_t nk = std::size_t(K);
    const std::size_t nl = std::size_t(lobe_count_);
    n_g_lobe_.assign(nl * nk, {});
    tbb::parallel_for(tbb::blocked_range<int>(0, K), [&](const tbb::blocked_range<int> &range) {
        std::vector<Rgbd> num(nl);
        std::vector<double> den(nl);
        for (int k = range.begin(); k != range.end(); ++k) {
            const double theta_k = table_theta(k);
            // (2) N_p^G at Marschner's difference angle θ_d = θ_k.
            std::fill(num.begin(), num.end(), Rgbd{});
            std::fill(den.begin(), den.end(), 0.0);
            const double td = theta_k;
            const double cos_d2 = sqr(std::cos(td));
            const double h_lo = -kHalfPi + std::fabs(td), h_hi = kHalfPi - std::fabs(td);
            const QuadratureRule h_rule =
                QuadratureRule::composite(h_lo, h_hi, params_.theta_panels, params_.points_per_panel);
            for (std::size_t m = 0; m < h_rule.x.size(); ++m) {
                const double th_h = h_rule.x[m];
                const double th_i = th_h - td, th_o = th_h + td;
                const double cos_i = std::cos(th_i);
                for (int p = 0; p < lobe_count_; ++p) {
                    const double beta = std::max(double(shapes_[std::size_t(p)].beta), double(params_.min_lobe_width));
                    den[std::size_t(p)] += h_rule.w[m] *
                        gaussian(th_h - shapes_[std::size_t(p)].alpha, beta * beta) * cos_i / cos_d2;
                }
                for (const double phi_o : rules.orientations) {
                    const std::unique_ptr<const FarFieldView> view = model.view(dir(th_o, phi_o));
                    for (int p = 0; p < lobe_count_; ++p) {
                        // (1/π)∫_fwd … dφ, averaged over orientations.
                        const double longitudinal = view->separable() ? view->longitudinal(p, th_i) : 1.0;
                        for (std::size_t n = 0; n < rules.forward.x.size(); ++n) {
                            const double w = h_rule.w[m] * rules.forward.w[n] * kInvPi * rules.weight_scale;
                            const Rgb v = view->separable() ? view->azimuthal(p, rules.forward.x[n])
                                                            : view->lobe_f_cos(p, dir(th_i, phi_o + rules.forward.x[n]));
                            for (int ch = 0; ch < 3; ++ch) num[std::size_t(p)].v[ch] += w * longitudinal * double(v[ch]);
                        }
                    }
                }
            }
            for (std::size_t p = 0; p < nl; ++p) {
                Rgbd ng;
                for (int ch = 0; ch < 3; ++ch) ng.v[ch] = den[p] > 0 ? num[p].v[ch] / den[p] : 0.0;
                n_g_lobe_[p * nk + std::size_t(k)] = ng;
            }
        }
    });
}

// (3) Per θ node, the averages over lobes and the multiple-backscatter terms (cheap, serial).
void DualScattering::derive_terms() {
    const std::size_t nk = std::size_t(params_.theta_count);
    const std::size_t nl = std::size_t(lobe_count_);
    a_f_.assign(nk, {});
    a_b_.assign(nk, {});
    alpha_f_.assign(nk, {});
    alpha_b_.assign(nk, {});
    beta2_f_.assign(nk, {});
    beta2_b_.assign(nk, {});
    big_a_b_.assign(nk, {});
    delta_b_.assign(nk, {});
    sigma2_b_.assign(nk, {});
    const double amax = params_.max_series_attenuation;
    const double db = params_.d_b;
    for (std::size_t k = 0; k < nk; ++k) {
        for (int ch = 0; ch < 3; ++ch) {
            double sf = 0, sb = 0, alf = 0, alb = 0, bf = 0, bb = 0;
            double mean_alpha = 0, mean_beta2 = 0;
            for (std::size_t p = 0; p < nl; ++p) {
                const double wf = std::max(0.0, a_f_lobe_[p * nk + k].v[ch]);
                const double wb = std::max(0.0, a_b_lobe_[p * nk + k].v[ch]);
                const double al = shapes_[p].alpha, be2 = sqr(double(shapes_[p].beta));
                sf += wf;
                sb += wb;
                alf += wf * al;
                alb += wb * al;
                bf += wf * be2;
                bb += wb * be2;
                mean_alpha += al / double(nl);
                mean_beta2 += be2 / double(nl);
            }
            // Light that passes a crossed fiber unscattered goes on forward, undeflected.
            sf += pass_[k];
            const double a_f = sf, a_b = sb;
            const double alpha_f = sf > 0 ? alf / sf : mean_alpha;
            const double alpha_b = sb > 0 ? alb / sb : mean_alpha;
            const double beta2_f = sf > 0 ? bf / sf : mean_beta2;
            const double beta2_b = sb > 0 ? bb / sb : mean_beta2;
            a_f_[k].v[ch] = a_f;
            a_b_[k].v[ch] = a_b;
            alpha_f_[k].v[ch] = alpha_f;
            alpha_b_[k].v[ch] = alpha_b;
            beta2_f_[k].v[ch] = beta2_f;
            beta2_b_[k].v[ch] = beta2_b;

            if (a_f > amax || a_b > amax) ++clamped_entries_;
            const double af = std::clamp(a_f, 0.0, amax), ab = std::clamp(a_b, 0.0, amax);
            const double af2 = af * af, ab2 = ab * ab, ab3 = ab2 * ab;
            const double om = 1.0 - af2;
            const double big_a_b = series_backscatter(af, ab, 1.0);
            const double delta_b = alpha_b * (1.0 - 2.0 * ab2 / (om * om)) +
                                   alpha_f * (2.0 * om * om + 4.0 * af2 * ab2) / (om * om * om);
            const double bf_ = beta2_f, bb_ = beta2_b;
            const double sig_den = ab + ab3;
            const double sigma_b =
                sig_den > 0 ? (1.0 + db * af2) *
                                  (ab * std::sqrt(2.0 * bf_ + bb_) + ab3 * std::sqrt(2.0 * bf_ + 3.0 * bb_)) /
                                  sig_den
                            : (1.0 + db * af2) * std::sqrt(2.0 * bf_ + bb_);
            big_a_b_[k].v[ch] = big_a_b;
            delta_b_[k].v[ch] = delta_b;
            sigma2_b_[k].v[ch] = sigma_b * sigma_b;
        }
    }
}

// ------------------------------------------------------------------------------------------
// Lookups

double DualScattering::table_theta(int k) const {
    return -kHalfPi + (k + 0.5) * kPi / params_.theta_count;
}

DualScattering::Rgbd DualScattering::lookup(const std::vector<Rgbd> &table, double theta,
                                            std::size_t offset) const {
    const int K = params_.theta_count;
    const double t = (theta + kHalfPi) * K / kPi - 0.5;  // fractional node index
    if (!(t > 0)) return table[offset];                   // also NaN
    if (t >= K - 1) return table[offset + std::size_t(K - 1)];
    const int i = int(t);
    const double f = t - i;
    const Rgbd &lo = table[offset + std::size_t(i)], &hi = table[offset + std::size_t(i) + 1];
    Rgbd out;
    for (int ch = 0; ch < 3; ++ch) out.v[ch] = (1 - f) * lo.v[ch] + f * hi.v[ch];
    return out;
}

Rgb DualScattering::to_rgb(const Rgbd &c) { return {float(c.v[0]), float(c.v[1]), float(c.v[2])}; }

Rgb DualScattering::lobe_forward_attenuation(int p, double theta) const {
    if (p < 0 || p >= lobe_count_) return {};
    return to_rgb(lookup(a_f_lobe_, theta, std::size_t(p) * std::size_t(params_.theta_count)));
}
Rgb DualScattering::lobe_backward_attenuation(int p, double theta) const {
    if (p < 0 || p >= lobe_count_) return {};
    return to_rgb(lookup(a_b_lobe_, theta, std::size_t(p) * std::size_t(params_.theta_count)));
}
double DualScattering::pass_through(double theta) const {
    const int K = params_.theta_count;
    const double t = (theta + kHalfPi) * K / kPi - 0.5;  // fractional node index, as lookup()
    if (!(t > 0)) return pass_.front();
    if (t >= K - 1) return pass_.back();
    const int i = int(t);
    const double f = t - i;
    return (1 - f) * pass_[std::size_t(i)] + f * pass_[std::size_t(i) + 1];
}
Rgb DualScattering::lobe_forward_azimuthal(int p, double theta_d) const {
    if (p < 0 || p >= lobe_count_) return {};
    return to_rgb(lookup(n_g_lobe_, theta_d, std::size_t(p) * std::size_t(params_.theta_count)));
}
LobeShape DualScattering::lobe_shape(int p) const {
    if (p < 0 || p >= lobe_count_) return {};
    return shapes_[std::size_t(p)];
}

Rgb DualScattering::forward_attenuation(double t) const { return to_rgb(lookup(a_f_, t)); }
Rgb DualScattering::backward_attenuation(double t) const { return to_rgb(lookup(a_b_, t)); }
Rgb DualScattering::crossing_attenuation(double t) const {
    const double s = std::sin(t);
    const Rgbd f = lookup(a_f_, t), b = lookup(a_b_, t);
    Rgbd a;
    for (int c = 0; c < 3; ++c) a.v[c] = std::clamp(f.v[c] + s * s * b.v[c], 0.0, 1.0);
    return to_rgb(a);
}
Rgb DualScattering::forward_shift(double t) const { return to_rgb(lookup(alpha_f_, t)); }
Rgb DualScattering::backward_shift(double t) const { return to_rgb(lookup(alpha_b_, t)); }
Rgb DualScattering::backscatter_attenuation(double t) const { return to_rgb(lookup(big_a_b_, t)); }
Rgb DualScattering::backscatter_shift(double t) const { return to_rgb(lookup(delta_b_, t)); }

Rgb DualScattering::forward_width(double t) const {
    const Rgbd v = lookup(beta2_f_, t);
    return {float(std::sqrt(v.v[0])), float(std::sqrt(v.v[1])), float(std::sqrt(v.v[2]))};
}
Rgb DualScattering::backward_width(double t) const {
    const Rgbd v = lookup(beta2_b_, t);
    return {float(std::sqrt(v.v[0])), float(std::sqrt(v.v[1])), float(std::sqrt(v.v[2]))};
}
Rgb DualScattering::backscatter_width(double t) const {
    const Rgbd v = lookup(sigma2_b_, t);
    return {float(std::sqrt(v.v[0])), float(std::sqrt(v.v[1])), float(std::sqrt(v.v[2]))};
}

Rgb DualScattering::forward_transmittance(double theta, int n_h) const {
    if (n_h < 0) return {};
    if (n_h == 0) return Rgb(1.0f);
    const Rgbd a = lookup(a_f_, theta);
    Rgb out;
    const double df = params_.d_f;
    out = {float(df * std::pow(std::max(0.0, a.v[0]), n_h)), float(df * std::pow(std::max(0.0, a.v[1]), n_h)),
           float(df * std::pow(std::max(0.0, a.v[2]), n_h))};
    return out;
}

Rgb DualScattering::forward_spread_variance(double theta, int n_h) const {
    if (n_h <= 0) return {};
    // The paper's σ_f² = n_h β̄_f² (the seed's source had n_h β̄_f, without the square).
    const Rgbd b2 = lookup(beta2_f_, theta);
    return {float(n_h * b2.v[0]), float(n_h * b2.v[1]), float(n_h * b2.v[2])};
}

// ------------------------------------------------------------------------------------------
// Shading

DualScattering::Rgbd DualScattering::backscatter(double theta, int depth) const {
    if (depth < 0) return lookup(big_a_b_, theta);
    const double amax = params_.max_series_attenuation;
    const Rgbd a_f = lookup(a_f_, theta), a_b = lookup(a_b_, theta);
    Rgbd out;
    for (int ch = 0; ch < 3; ++ch) {
        const double af = std::clamp(a_f.v[ch], 0.0, amax), ab = std::clamp(a_b.v[ch], 0.0, amax);
        out.v[ch] = series_backscatter(af, ab, 1.0 - std::pow(af * af, depth));
    }
    return out;
}

Rgb DualScattering::backscatter_attenuation(double theta, int depth) const {
    return to_rgb(backscatter(theta, depth));
}

DualScattering::Rgbd DualScattering::local_term(double theta_i, double theta_o, int depth) const {
    const double theta_h = 0.5 * (theta_i + theta_o);
    const double theta_d = 0.5 * (theta_o - theta_i);
    const double cos_i = std::max(0.0, std::cos(theta_i));
    const double cos_d2 = std::max(sqr(std::cos(theta_d)), 1e-12);
    const Rgbd big_a = backscatter(theta_i, depth);
    const Rgbd delta = lookup(delta_b_, theta_i);
    const Rgbd sig2 = lookup(sigma2_b_, theta_i);
    Rgbd out;
    for (int ch = 0; ch < 3; ++ch) {
        const double v = std::max(sig2.v[ch], 1e-12);
        const double f_back = big_a.v[ch] * gaussian(theta_h - delta.v[ch], v) / (kPi * cos_d2);
        out.v[ch] = params_.d_b * f_back * cos_i;
    }
    return out;
}

DualScattering::Rgbd DualScattering::scattered_term(double theta_i, double theta_o, const Rgbd &t_f,
                                                    const Rgbd &s_f2, int depth) const {
    const double theta_h = 0.5 * (theta_i + theta_o);
    const double theta_d = 0.5 * (theta_o - theta_i);
    const double cos_i = std::max(0.0, std::cos(theta_i));
    const double cos_d2 = std::max(sqr(std::cos(theta_d)), 1e-12);
    const double db = params_.d_b, df = params_.d_f;
    const Rgbd big_a = backscatter(theta_i, depth);
    const Rgbd delta = lookup(delta_b_, theta_i);
    const Rgbd sig2 = lookup(sigma2_b_, theta_i);
    std::array<Rgbd, 16> ng{};
    for (int p = 0; p < lobe_count_; ++p)
        ng[std::size_t(p)] = lookup(n_g_lobe_, theta_d, std::size_t(p) * std::size_t(params_.theta_count));
    Rgbd out;
    for (int ch = 0; ch < 3; ++ch) {
        const double spread = std::max(0.0, s_f2.v[ch]);
        double f_s = 0;
        for (int p = 0; p < lobe_count_; ++p) {
            const LobeShape &s = shapes_[std::size_t(p)];
            const double var = std::max(sqr(double(s.beta)) + spread, 1e-12);
            f_s += gaussian(theta_h - s.alpha, var) * ng[std::size_t(p)].v[ch] / cos_d2;
        }
        const double var_b = std::max(sig2.v[ch] + spread, 1e-12);
        const double f_back = big_a.v[ch] * gaussian(theta_h - delta.v[ch], var_b) / (kPi * cos_d2);
        out.v[ch] = t_f.v[ch] * df * (f_s + kPi * db * f_back) * cos_i;
    }
    return out;
}

Rgb DualScattering::local_f_cos(float theta_i, float theta_o, int depth) const {
    return to_rgb(local_term(theta_i, theta_o, depth));
}

Rgb DualScattering::scattered_f_cos(float theta_i, float theta_o, Rgb transmittance, Rgb spread_variance,
                                    int depth) const {
    Rgbd t_f, s_f2;
    for (int ch = 0; ch < 3; ++ch) {
        t_f.v[ch] = transmittance[ch];
        s_f2.v[ch] = spread_variance[ch];
    }
    return to_rgb(scattered_term(theta_i, theta_o, t_f, s_f2, depth));
}

Rgb DualScattering::multiple_f_cos(float theta_i_f, float theta_o_f, int n_h) const {
    if (n_h < 0) return {};
    const double theta_i = theta_i_f, theta_o = theta_o_f;
    if (n_h == 0) return to_rgb(local_term(theta_i, theta_o, -1));
    const Rgbd a_f = lookup(a_f_, theta_i);
    const Rgbd b2f = lookup(beta2_f_, theta_i);
    Rgbd t_f, s_f2;
    for (int ch = 0; ch < 3; ++ch) {
        t_f.v[ch] = params_.d_f * std::pow(std::max(0.0, a_f.v[ch]), n_h);
        s_f2.v[ch] = n_h * b2f.v[ch];
    }
    return to_rgb(scattered_term(theta_i, theta_o, t_f, s_f2, -1));
}

}  // namespace hairis
