// Float data in text mesh files: OBJ and OFF carry no type, and float32 data is usually written to
// them as the shortest decimal of each float. Reading those decimals as doubles would turn float
// data into double data (twice the bits to code losslessly), so readers give such meshes back as
// floats and writers print them the same way: a file's text survives a round trip either way.
#pragma once

#include <cfloat>
#include <charconv>
#include <cmath>
#include <string>
#include <system_error>
#include <vector>

#include "amc/mesh.h"
#include "mesh/text_number.h"

namespace amc::text {

// What a coordinate read from text says about the data it was printed from.
enum class FloatText {
    not_float,    // neither a float32 nor the shortest decimal of one
    exact,        // a float32 itself (0.5, 3)
    ambiguous,    // the shortest decimal of a float, but short enough for a double (0.1)
    distinctive,  // the shortest decimal of a float, 8 or 9 digits: only float data prints these
};

// Digits from the first to the last non-zero one of a printed decimal ("1.25e-07": 3).
inline int significant_digits(const char* begin, const char* end) {
    int first = -1, last = -1, position = 0;
    for (const char* c = begin; c != end && *c != 'e'; ++c) {
        if (*c < '0' || *c > '9') continue;
        if (*c != '0') {
            if (first < 0) first = position;
            last = position;
        }
        ++position;
    }
    return first < 0 ? 0 : last - first + 1;
}

// Classifies `value` and gives the float32 behind it in `as_float` (unless not_float).
inline FloatText classify_float_text(double value, float& as_float) {
    constexpr int kDigitsOnlyFloatsPrint = 8;  // doubles print 15-17, short data 7 or fewer
    const float f = static_cast<float>(value);
    if (!(std::fabs(f) <= FLT_MAX)) return FloatText::not_float;
    as_float = f;
    if (static_cast<double>(f) == value) return FloatText::exact;
    char buf[32];
    const auto printed = std::to_chars(buf, buf + sizeof buf, f);
    double back = 0;
    const auto parsed = std::from_chars(buf, printed.ptr, back);
    if (printed.ec != std::errc() || parsed.ec != std::errc() || back != value) return FloatText::not_float;
    // The float's shortest decimal reads back as `value`, so it is also the double's shortest: a
    // shorter decimal that close would differ from it by at least 10^-9 relatively.
    return significant_digits(buf, printed.ptr) >= kDigitsOnlyFloatsPrint ? FloatText::distinctive
                                                                            : FloatText::ambiguous;
}

// The double that the shortest decimal of `f` reads as.
inline double float_decimal_value(float f) {
    char buf[32];
    const auto printed = std::to_chars(buf, buf + sizeof buf, f);
    double back = f;
    std::from_chars(buf, printed.ptr, back);
    return back;
}

// Makes a mesh read from text single precision when its coordinates are float data: each is a
// float or the shortest decimal of one, and all are exact or one is distinctive. Each coordinate
// is then replaced by its float; otherwise the mesh is left in double precision, unchanged.
inline void adopt_float_text(TriangleMesh& mesh) {
    std::vector<Vec3> floats(mesh.positions.size());
    bool all_exact = true, distinctive_seen = false;
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const double coordinates[3] = {mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z};
        float xyz[3];
        for (int k = 0; k < 3; ++k) {
            const FloatText kind = classify_float_text(coordinates[k], xyz[k]);
            if (kind == FloatText::not_float) {
                mesh.single_precision = false;
                return;
            }
            all_exact = all_exact && kind == FloatText::exact;
            distinctive_seen = distinctive_seen || kind == FloatText::distinctive;
        }
        floats[v] = {xyz[0], xyz[1], xyz[2]};
    }
    mesh.single_precision = all_exact || distinctive_seen;
    if (mesh.single_precision) mesh.positions = std::move(floats);
}

// Whether a single-precision mesh printed as float decimals reads back as floats (some decimal is
// distinctive); if not, it is printed as doubles, which read back as exact floats.
inline bool prints_as_float_text(const TriangleMesh& mesh) {
    if (!mesh.single_precision) return false;
    for (const Vec3& p : mesh.positions) {
        for (double c : {p.x, p.y, p.z}) {
            float f;
            if (classify_float_text(float_decimal_value(static_cast<float>(c)), f) == FloatText::distinctive) {
                return true;
            }
        }
    }
    return false;
}

// Appends a vertex line, as float decimals when `float_text`.
inline void append_position(std::string& out, const Vec3& p, bool float_text) {
    if (float_text) {
        append_line(out, static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
    } else {
        append_line(out, p.x, p.y, p.z);
    }
}

}  // namespace amc::text
