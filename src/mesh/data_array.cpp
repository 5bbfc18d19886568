// DataArray: the typed values of one point or cell array; the cell arrays of a leaf mesh.
#include <variant>
#include <vector>

#include "amc/mesh.h"

namespace amc {

std::size_t DataArray::size() const {
    return std::visit([](const auto& v) { return v.size(); }, values);
}

double DataArray::value(std::size_t index) const {
    return std::visit([index](const auto& v) { return static_cast<double>(v.at(index)); }, values);
}

std::vector<DataArray> cell_data_arrays(const CellData& cells) {
    std::vector<DataArray> arrays;
    if (!cells.level.empty()) arrays.push_back({"level", 1, cells.level});
    if (!cells.is_green.empty()) arrays.push_back({"green", 1, cells.is_green});
    return arrays;
}

}  // namespace amc
