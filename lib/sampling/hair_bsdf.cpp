#include "sampling/hair_bsdf.h"

namespace hairis {

Expected<HairShading> HairShading::create(std::shared_ptr<const ShadingModel> model,
                                          std::shared_ptr<const Sampler> sampler) {
    if (!sampler) return Error{"hair shading: no sampler was given"};
    if (sampler->model() && sampler->model() != model.get())
        return Error{model ? "hair shading: the sampler was built for another fiber"
                           : "hair shading: the sampler needs its fiber, and none was given"};
    HairShading h;
    h.model_ = std::move(model);
    h.sampler_ = std::move(sampler);
    return h;
}

}  // namespace hairis
