// VTU reader. Two passes: the structure (vtu_layout.h: pieces, their arrays and where each
// array's data is) up to the appended data, then each array decoded (vtu_arrays.h) and the pieces
// joined into one mesh with its point and cell data.
#include "mesh/vtu_reader.h"

#include "mesh/text_number.h"
#include "mesh/vtk_types.h"
#include "mesh/vtu_arrays.h"
#include "mesh/vtu_layout.h"

#include <algorithm>
#include <limits>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace amc {

using vtu::ArrayElement;
using vtu::describe;
using vtu::fail;
using vtu::kMaxElements;
using vtu::Layout;
using vtu::PieceElement;
using vtu::Section;

namespace {

// Calls f(i, value) for each value of an integer array (64-bit unsigned values past INT64_MAX
// come as INT64_MAX, out of every range the callers accept).
template <typename F>
void for_each_integer(const DataArray& array, F f) {
    std::visit(
        [&](const auto& v) {
            using T = typename std::decay_t<decltype(v)>::value_type;
            if constexpr (std::is_integral_v<T>) {
                for (std::size_t i = 0; i < v.size(); ++i) {
                    if constexpr (std::is_same_v<T, uint64_t>) {
                        f(i, static_cast<int64_t>(std::min<uint64_t>(v[i], std::numeric_limits<int64_t>::max())));
                    } else {
                        f(i, static_cast<int64_t>(v[i]));
                    }
                }
            }
        },
        array.values);
}

template <typename T>
void append_values(DataArray::Values& to, const DataArray::Values& from) {
    std::get<std::vector<T>>(to).insert(std::get<std::vector<T>>(to).end(),
                                        std::get<std::vector<T>>(from).begin(),
                                        std::get<std::vector<T>>(from).end());
}

// Adds one piece's arrays to those of the earlier pieces (the first piece sets the list).
void append_data(std::vector<DataArray>& all, std::vector<DataArray>&& piece, bool first,
                 const char* kind, std::size_t piece_index, const std::string& what) {
    if (first) {
        all = std::move(piece);
        return;
    }
    if (piece.size() != all.size()) {
        fail(what, "piece " + std::to_string(piece_index) + " has " + std::to_string(piece.size()) + " " +
                       kind + " arrays, piece 0 has " + std::to_string(all.size()), ErrorCode::invalid_input);
    }
    for (std::size_t i = 0; i < all.size(); ++i) {
        if (piece[i].name != all[i].name || piece[i].type() != all[i].type() ||
            piece[i].components != all[i].components) {
            fail(what, "piece " + std::to_string(piece_index) + "'s " + kind + " array " +
                           text::quote_token(piece[i].name) + " does not match piece 0's " +
                           text::quote_token(all[i].name) + " (name, type and components)", ErrorCode::invalid_input);
        }
        std::visit(
            [&](auto& v) {
                using T = typename std::decay_t<decltype(v)>::value_type;
                append_values<T>(all[i].values, piece[i].values);
            },
            all[i].values);
    }
}

const ArrayElement* find_cells_array(const PieceElement& piece, const char* name) {
    for (const ArrayElement& a : piece.arrays) {
        if (a.section == Section::cells && a.name == name) return &a;
    }
    return nullptr;
}

}  // namespace

VtuMesh parse_vtu(std::string_view bytes, const std::string& what, unsigned threads) {
    const Layout layout = vtu::read_layout(bytes, what);
    VtuMesh out;
    out.mesh.single_precision = true;
    uint64_t first_point = 0, first_cell = 0;
    for (std::size_t k = 0; k < layout.pieces.size(); ++k) {
        const PieceElement& piece = layout.pieces[k];
        const std::string prefix = layout.pieces.size() > 1 ? "piece " + std::to_string(k) + ": " : "";
        if (piece.points > kMaxElements - first_point || piece.cells > kMaxElements - first_cell) {
            fail(what, prefix + "declares " + std::to_string(piece.points) + " points and " +
                           std::to_string(piece.cells) + " cells, more than 2^32 - 1 in all", ErrorCode::limit_exceeded);
        }
        const auto need = [&](const char* name) -> const ArrayElement& {
            const ArrayElement* a = find_cells_array(piece, name);
            if (!a) fail(what, prefix + "Cells has no '" + name + "' DataArray");
            return *a;
        };
        const auto integers = [&](const ArrayElement& a, uint64_t tuples) {
            if (!is_integer(a.type) || a.components != 1) {
                fail(what, describe(a, prefix) + ": has type " + std::string(vtk_type_name(a.type)) +
                               " with " + std::to_string(a.components) +
                               " components; one integer per cell is needed", ErrorCode::invalid_input);
            }
            return vtu::decode_array(layout, a, tuples, prefix, what, threads);
        };

        // Types first, so that a mesh of quads is refused as such, whatever its offsets say.
        const DataArray types = integers(need("types"), piece.cells);
        for_each_integer(types, [&](std::size_t i, int64_t type) {
            if (type != kVtkTriangle && type != kVtkPolygon) {
                fail(what, "cell " + std::to_string(first_cell + i) + " is " + describe_vtk_cell_type(type) +
                               "; only triangles (VTK type 5) and polygons of 3 points are read", ErrorCode::invalid_input);
            }
        });
        const DataArray offsets = integers(need("offsets"), piece.cells);
        for_each_integer(offsets, [&](std::size_t i, int64_t end) {
            // Every earlier cell had 3 points, so this one starts at 3i.
            const int64_t begin = 3 * static_cast<int64_t>(i);
            if (end != begin + 3) {
                const int64_t type = static_cast<int64_t>(types.value(i));
                fail(what, "cell " + std::to_string(first_cell + i) + " is " + describe_vtk_cell_type(type) +
                               " of " + (end >= begin ? std::to_string(end - begin) : std::string("fewer than 0")) +
                               " points (offset " + std::to_string(end) +
                               "); only cells of 3 points are read", ErrorCode::invalid_input);
            }
        });
        const DataArray connectivity = integers(need("connectivity"), 3 * piece.cells);

        const ArrayElement* points = nullptr;
        for (const ArrayElement& a : piece.arrays) {
            if (a.section == Section::points) {
                points = &a;
                break;
            }
        }
        if (!points && piece.points > 0) fail(what, prefix + "no Points DataArray");
        if (points) {
            if (points->components != 3) {
                fail(what, describe(*points, prefix) + ": has " + std::to_string(points->components) +
                               " components; points need 3", ErrorCode::invalid_input);
            }
            const DataArray coordinates = vtu::decode_array(layout, *points, piece.points, prefix, what, threads);
            if (points->type != ValueType::float32) out.mesh.single_precision = false;
            // Exact for one piece, doubling over several: an exact reserve for each piece copied all
            // the earlier pieces' points, quadratic in the pieces (docs/FUZZING.md).
            if (out.mesh.positions.capacity() < first_point + piece.points) {
                out.mesh.positions.reserve(std::max<std::size_t>(first_point + piece.points, 2 * out.mesh.positions.capacity()));
            }
            std::visit(
                [&](const auto& v) {
                    for (std::size_t i = 0; i + 2 < v.size(); i += 3) {
                        out.mesh.positions.push_back({static_cast<double>(v[i]), static_cast<double>(v[i + 1]),
                                                      static_cast<double>(v[i + 2])});
                    }
                },
                coordinates.values);
        }

        out.mesh.triangles.resize(first_cell + piece.cells);
        for_each_integer(connectivity, [&](std::size_t i, int64_t index) {
            if (index < 0 || static_cast<uint64_t>(index) >= piece.points) {
                fail(what, "cell " + std::to_string(first_cell + i / 3) + " refers to point " +
                               std::to_string(index) + ", out of range (" + prefix +
                               std::to_string(piece.points) + " points)");
            }
            out.mesh.triangles[first_cell + i / 3][i % 3] = static_cast<uint32_t>(first_point + index);
        });

        std::vector<DataArray> point_data, cell_data;
        for (const ArrayElement& a : piece.arrays) {
            if (a.section == Section::point_data) point_data.push_back(vtu::decode_array(layout, a, piece.points, prefix, what, threads));
            if (a.section == Section::cell_data) cell_data.push_back(vtu::decode_array(layout, a, piece.cells, prefix, what, threads));
        }
        append_data(out.point_data, std::move(point_data), k == 0, "point data", k, what);
        append_data(out.cell_data, std::move(cell_data), k == 0, "cell data", k, what);
        first_point += piece.points;
        first_cell += piece.cells;
    }
    if (out.mesh.positions.empty()) out.mesh.single_precision = false;
    return out;
}

}  // namespace amc
