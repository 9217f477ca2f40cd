#include "fiber/fiber.h"

namespace hairis {

namespace {

class GenericView final : public FarFieldView {
  public:
    GenericView(const FiberModel &model, Vec3 wo) : model_(model), wo_(wo) {}
    Rgb lobe_f_cos(int p, Vec3 wi) const override { return model_.lobe_f_cos(p, wi, wo_); }

  private:
    const FiberModel &model_;
    Vec3 wo_;
};

}  // namespace

std::unique_ptr<const FarFieldView> FiberModel::view(Vec3 wo) const {
    return std::make_unique<GenericView>(*this, wo);
}

}  // namespace hairis
