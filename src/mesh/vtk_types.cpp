// VTK's type names and cell type numbers (vtkType.h, vtkCellType.h).
#include "mesh/vtk_types.h"

namespace amc {
namespace {

// In ValueType order.
constexpr std::string_view kTypeNames[] = {"Int8",  "UInt8",  "Int16", "UInt16",  "Int32",
                                           "UInt32", "Int64", "UInt64", "Float32", "Float64"};
constexpr std::size_t kTypeSizes[] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};

}  // namespace

std::string_view vtk_type_name(ValueType type) { return kTypeNames[static_cast<int>(type)]; }

bool parse_vtk_type_name(std::string_view name, ValueType& type) {
    for (std::size_t i = 0; i < std::size(kTypeNames); ++i) {
        if (name == kTypeNames[i]) {
            type = static_cast<ValueType>(i);
            return true;
        }
    }
    // Old VTK files spell the id type "vtkIdType" (as wide as Int32 or Int64, which the header
    // words cannot tell); we refuse them with the generic message rather than guess.
    return false;
}

std::size_t value_size(ValueType type) { return kTypeSizes[static_cast<int>(type)]; }

bool is_integer(ValueType type) { return type != ValueType::float32 && type != ValueType::float64; }

std::string describe_vtk_cell_type(int64_t type) {
    static const struct {
        int64_t type;
        const char* name;
    } names[] = {{1, "vertex"},         {2, "poly-vertex"},     {3, "line"},
                 {4, "poly-line"},      {5, "triangle"},        {6, "triangle strip"},
                 {7, "polygon"},        {8, "pixel"},           {9, "quad"},
                 {10, "tetrahedron"},   {11, "voxel"},          {12, "hexahedron"},
                 {13, "wedge"},         {14, "pyramid"},        {15, "pentagonal prism"},
                 {16, "hexagonal prism"}, {21, "quadratic edge"}, {22, "quadratic triangle"},
                 {23, "quadratic quad"}, {24, "quadratic tetrahedron"},
                 {25, "quadratic hexahedron"}, {42, "polyhedron"}, {68, "Lagrange curve"},
                 {69, "Lagrange triangle"}, {70, "Lagrange quadrilateral"},
                 {71, "Lagrange tetrahedron"}, {72, "Lagrange hexahedron"}};
    const std::string number = "(VTK type " + std::to_string(type) + ")";
    for (const auto& n : names) {
        if (n.type == type) {
            const char first = n.name[0];
            const bool vowel = first == 'a' || first == 'e' || first == 'i' || first == 'o' ||
                               first == 'u';
            return std::string(vowel ? "an " : "a ") + n.name + " " + number;
        }
    }
    return "a cell of unknown type " + number;
}

}  // namespace amc
