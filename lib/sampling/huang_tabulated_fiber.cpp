#include "sampling/huang_tabulated_fiber.h"

#include <string>

#include "sampling/table_set.h"

namespace hairis {

HuangTabulatedPoint::HuangTabulatedPoint(const HuangTabulatedFiber &model, const FiberHit &hit)
    : FiberPoint(hit), point_(model.fiber(), hit), query_(model.table().locate(point_.to_huang(hit.wo))),
      f_(&model.f_table()) {}

Rgb HuangTabulatedPoint::f(Vec3 wi) const {
    if (point_.near_field()) return point_.f(wi);
    return point_.f_reflection(wi) + f_->f_cos(query_, point_.to_huang(wi));
}

Expected<HuangTabulatedFiber> HuangTabulatedFiber::create(std::shared_ptr<const HuangFiber> fiber,
                                                          std::shared_ptr<const HuangSamplingTable> table) {
    if (!fiber) return Error{"tabulated Huang fiber: no Huang fiber was given"};
    if (!table || !table->table) return Error{"tabulated Huang fiber: no Huang table was given"};
    if (!table->f)
        return Error{"tabulated Huang fiber: the Huang table has no baked f; bake the table again", ErrorKind::InvalidTable};
    const std::string parameters = canonical_parameters(huang_parameters(fiber->params()));
    if (table->parameters != parameters)
        return Error{"tabulated Huang fiber: the table was baked for \"" + table->parameters + "\", not for \"" +
                         parameters + "\"; bake a table for this fiber",
                     ErrorKind::InvalidTable};
    return HuangTabulatedFiber(std::move(fiber), std::move(table));
}

}  // namespace hairis
