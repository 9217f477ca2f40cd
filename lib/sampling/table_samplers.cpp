#include "sampling/table_samplers.h"

#include <cmath>
#include <string>

#include "core/frame.h"

namespace hairis {

namespace {

// The view's azimuth as a rotation, so that φ = φ_i − φ_o needs one atan2.
struct ViewAzimuth {
    float cos_phi_o = 0, sin_phi_o = -1;
    explicit ViewAzimuth(Vec3 wo) {
        const float r = std::sqrt(wo.y * wo.y + wo.z * wo.z);
        if (r > 0.0f) cos_phi_o = wo.y / r, sin_phi_o = wo.z / r;
    }
    float relative(Vec3 wi) const {
        return std::atan2(wi.z * cos_phi_o - wi.y * sin_phi_o, wi.y * cos_phi_o + wi.z * sin_phi_o);
    }
};

class FarTablePoint final : public SamplerPoint {
  public:
    FarTablePoint(const DirectTable &table, Vec3 wo)
        : table_(&table), at_(table.locate(safe_asin(wo.x))), view_(wo) {}
    std::optional<DirectionSample> sample(float u0, float u1, float u2) const override {
        const TableSample s = table_->sample(at_, u0, u1, u2);
        if (!(s.pdf > 0.0f)) return std::nullopt;
        return DirectionSample{s.local_direction(view_.cos_phi_o, view_.sin_phi_o), s.pdf};
    }
    float pdf(Vec3 wi) const override { return table_->pdf_sin(at_, wi.x, view_.relative(wi)); }

  private:
    const DirectTable *table_;
    NodeBlend at_;
    ViewAzimuth view_;
};

class MultipleTablePoint final : public SamplerPoint {
  public:
    MultipleTablePoint(const MultipleTable &table, int strand, Vec3 wo)
        : table_(&table), strand_(strand), at_(table.locate(safe_asin(wo.x))), view_(wo) {}
    std::optional<DirectionSample> sample(float u0, float u1, float u2) const override {
        const TableSample s = table_->sample(strand_, at_, u0, u1, u2);
        if (!(s.pdf > 0.0f)) return std::nullopt;
        return DirectionSample{s.local_direction(view_.cos_phi_o, view_.sin_phi_o), s.pdf};
    }
    float pdf(Vec3 wi) const override { return table_->pdf_sin(strand_, at_, wi.x); }

  private:
    const MultipleTable *table_;
    int strand_;
    NodeBlend at_;
    ViewAzimuth view_;
};

}  // namespace

const SamplerPoint &FarTableSampler::at(const FiberHit &hit, const FiberPoint *, ScratchBuffer &scratch) const {
    return scratch.make<FarTablePoint>(*table_, hit.wo);
}

Expected<MultipleTableSampler> MultipleTableSampler::create(std::shared_ptr<const MultipleTable> table, int n_h) {
    if (!table) return Error{"multiple table: none was given"};
    const int strand = table->strand_index(n_h);
    if (strand < 0) {
        std::string held;
        for (int v : table->n_h_values()) held += (held.empty() ? "" : ", ") + std::to_string(v);
        return Error{"the multiple table has no n_h = " + std::to_string(n_h) + " (it holds " + held + ")"};
    }
    return MultipleTableSampler(std::move(table), strand);
}

const SamplerPoint &MultipleTableSampler::at(const FiberHit &hit, const FiberPoint *, ScratchBuffer &scratch) const {
    return scratch.make<MultipleTablePoint>(*table_, strand_, hit.wo);
}

}  // namespace hairis
