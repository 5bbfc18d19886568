// DataArray: the typed values of one point or cell array.
#include <variant>

#include "amc/mesh.h"

namespace amc {

std::size_t DataArray::size() const {
    return std::visit([](const auto& v) { return v.size(); }, values);
}

double DataArray::value(std::size_t index) const {
    return std::visit([index](const auto& v) { return static_cast<double>(v.at(index)); }, values);
}

}  // namespace amc
