// The Python module amcodec._amcodec: numpy arrays in and out of the public C++ API. Errors are
// raised as amcodec.Error with the library's message; long calls release the GIL.
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/import.h>
#include <amc/numbering.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <optional>
#include <string>

namespace py = pybind11;
using namespace amc;

namespace {

using PointArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IndexArray = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;

// A numpy (n, 3) array of coordinates; float32 input keeps single precision (bit-exact files).
TriangleMesh mesh_from_arrays(const py::array& points, const py::array& triangles, const char* what) {
    TriangleMesh mesh;
    mesh.single_precision = points.dtype().is(py::dtype::of<float>());
    const PointArray p = PointArray::ensure(points);
    const IndexArray t = IndexArray::ensure(triangles);
    if (!p || p.ndim() != 2 || p.shape(1) != 3) throw Error(std::string(what) + ": points must be an (n, 3) array");
    if (!t || t.ndim() != 2 || t.shape(1) != 3) throw Error(std::string(what) + ": triangles must be an (m, 3) integer array");
    auto pv = p.unchecked<2>();
    mesh.positions.resize(size_t(p.shape(0)));
    for (py::ssize_t i = 0; i < p.shape(0); ++i) mesh.positions[size_t(i)] = {pv(i, 0), pv(i, 1), pv(i, 2)};
    auto tv = t.unchecked<2>();
    mesh.triangles.resize(size_t(t.shape(0)));
    for (py::ssize_t i = 0; i < t.shape(0); ++i) {
        for (int c = 0; c < 3; ++c) {
            const int64_t v = tv(i, c);
            if (v < 0 || v >= int64_t(mesh.positions.size()))
                throw Error(std::string(what) + ": triangle " + std::to_string(i) + " has vertex index " + std::to_string(v) +
                            " out of range");
            mesh.triangles[size_t(i)][c] = uint32_t(v);
        }
    }
    validate_triangle_mesh(mesh, what);
    return mesh;
}

py::array points_array(const TriangleMesh& mesh) {
    const size_t n = mesh.positions.size();
    if (mesh.single_precision) {
        py::array_t<float> out({py::ssize_t(n), py::ssize_t(3)});
        auto o = out.mutable_unchecked<2>();
        for (size_t i = 0; i < n; ++i) {
            o(i, 0) = float(mesh.positions[i].x);
            o(i, 1) = float(mesh.positions[i].y);
            o(i, 2) = float(mesh.positions[i].z);
        }
        return std::move(out);
    }
    py::array_t<double> out({py::ssize_t(n), py::ssize_t(3)});
    auto o = out.mutable_unchecked<2>();
    for (size_t i = 0; i < n; ++i) {
        o(i, 0) = mesh.positions[i].x;
        o(i, 1) = mesh.positions[i].y;
        o(i, 2) = mesh.positions[i].z;
    }
    return std::move(out);
}

template <class T>
py::array_t<T> vector_array(const std::vector<T>& values) {
    py::array_t<T> out(py::ssize_t(values.size()));
    if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
    return out;
}

py::array_t<uint32_t> triangles_array(const std::vector<Triangle>& triangles) {
    py::array_t<uint32_t> out({py::ssize_t(triangles.size()), py::ssize_t(3)});
    if (!triangles.empty()) std::memcpy(out.mutable_data(), triangles.data(), triangles.size() * sizeof(Triangle));
    return out;
}

// What decode and leaf_mesh return: a mesh with its cell data, and the stored numbering, if any.
py::dict mesh_dict(const TriangleMesh& mesh, const CellData& cells, const LeafNumbering* numbering) {
    py::dict d;
    d["points"] = points_array(mesh);
    d["triangles"] = triangles_array(mesh.triangles);
    d["level"] = vector_array(cells.level);
    d["green"] = vector_array(cells.is_green);
    if (numbering != nullptr && !numbering->empty()) {
        py::dict n;
        n["vertex"] = vector_array(numbering->vertex);
        n["face"] = vector_array(numbering->face);
        n["rotation"] = vector_array(numbering->rotation);
        d["numbering"] = n;
    } else {
        d["numbering"] = py::none();
    }
    return d;
}

py::dict stats_dict(const EncodeStats& s) {
    py::dict d;
    d["total_bytes"] = s.total_bytes;
    d["base_connectivity_bytes"] = s.base_connectivity_bytes;
    d["base_geometry_bytes"] = s.base_geometry_bytes;
    d["hierarchy_bytes"] = s.hierarchy_bytes;
    d["geometry_bytes"] = s.geometry_bytes;
    d["numbering_bytes"] = s.numbering_bytes;
    d["header_bytes"] = s.header_bytes;
    d["framing_bytes"] = s.framing_bytes;
    d["faces"] = s.faces;
    d["vertices"] = s.vertices;
    d["nodes"] = s.nodes;
    d["levels"] = s.levels;
    d["base_triangles"] = s.base_triangles;
    d["max_error"] = s.max_error;
    return d;
}

ImportedHierarchy import_arrays(const TriangleMesh& mesh, const py::object& base) {
    if (base.is_none()) {
        // Until base detection (issue 23, part 2) lands: the mesh is its own base.
        ImportedHierarchy own;
        own.hierarchy = Hierarchy(mesh);
        for (uint32_t i = 0; i < mesh.positions.size(); ++i) own.vertex_of_input.push_back(i);
        return own;
    }
    const py::tuple pair = base.cast<py::tuple>();
    if (pair.size() != 2) throw Error("base: expected a (points, triangles) pair");
    const TriangleMesh base_mesh = mesh_from_arrays(pair[0].cast<py::array>(), pair[1].cast<py::array>(), "base mesh");
    py::gil_scoped_release release;
    return import_leaf_mesh(base_mesh, mesh, {}, "mesh");
}

py::bytes to_bytes(const std::vector<uint8_t>& data) { return py::bytes(reinterpret_cast<const char*>(data.data()), data.size()); }

}  // namespace

PYBIND11_MODULE(_amcodec, m) {
    m.doc() = "amcodec: lossless compression of adaptive red-green multiresolution meshes (C++ core)";
    static py::exception<Error> error(m, "Error", PyExc_ValueError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Error& e) {
            error(e.what());
        }
    });

    py::class_<Hierarchy>(m, "Hierarchy", "A base triangle mesh and a forest of red-green quad-trees, one per base triangle.")
        .def(py::init([](const py::array& points, const py::array& triangles) {
                 return Hierarchy(mesh_from_arrays(points, triangles, "base mesh"));
             }),
             py::arg("points"), py::arg("triangles"), "The unrefined hierarchy over a base mesh ((n, 3) points, (m, 3) triangles).")
        .def_static("read", &read_hierarchy, py::arg("path"), "Reads a hierarchy file (.amh).")
        .def("write", [](const Hierarchy& h, const std::string& path) { write_hierarchy(path, h); }, py::arg("path"),
             "Writes a hierarchy file (.amh).")
        .def_property_readonly("root_count", &Hierarchy::root_count)
        .def_property_readonly("node_count", &Hierarchy::node_count)
        .def_property_readonly("leaf_count", &Hierarchy::leaf_count)
        .def_property_readonly("vertex_count", &Hierarchy::vertex_count)
        .def_property_readonly("depth", &Hierarchy::depth)
        .def("is_leaf", &Hierarchy::is_leaf, py::arg("node"))
        .def("level", &Hierarchy::level, py::arg("node"))
        .def("leaves", &Hierarchy::leaves, "Leaf node ids in breadth-first order.")
        .def("refine", [](Hierarchy& h, NodeId n) {
                 if (!h.is_alive(n)) throw Error("refine: no node " + std::to_string(n));
                 return h.refine(n);
             }, py::arg("node"), "Red-refines a leaf with balance and closure; returns the number of nodes split.")
        .def("coarsen", [](Hierarchy& h, NodeId n) {
                 if (!h.is_alive(n)) throw Error("coarsen: no node " + std::to_string(n));
                 return h.coarsen(n);
             }, py::arg("node"), "Removes a node's four leaf children where balance allows; returns whether it did.")
        .def("check", &check_invariants, "Every structural invariant: '' if valid, else the first violation.")
        .def("leaf_mesh", [](const Hierarchy& h, int level) {
                 const LeafMesh leaf = extract_leaf_mesh(h, level);
                 return mesh_dict(leaf.mesh, leaf.cells, nullptr);
             }, py::arg("level") = -1,
             "The conforming leaf mesh (or the mesh of one level): dict with points, triangles, level, green.")
        .def("encode", [](const Hierarchy& h, int quantize) {
                 EncodeOptions options;
                 options.quantize_bits = quantize;
                 std::vector<uint8_t> data;
                 {
                     py::gil_scoped_release release;
                     data = encode(h, options);
                 }
                 return to_bytes(data);
             }, py::arg("quantize") = 0, "Compresses to .amc bytes (quantize: 0 bit-exact, else bits per axis).")
        .def("identical", [](const Hierarchy& a, const Hierarchy& b) { return identical(a, b); }, py::arg("other"),
             "Same base, forest, diagonals and bit-identical positions (canonical order).");

    m.def("encode", [](const py::array& points, const py::array& triangles, const py::object& base, bool keep_numbering,
                       int quantize, bool return_stats) -> py::object {
              const TriangleMesh mesh = mesh_from_arrays(points, triangles, "mesh");
              ImportedHierarchy imported = import_arrays(mesh, base);
              EncodeStats stats;
              std::vector<uint8_t> data;
              {
                  py::gil_scoped_release release;
                  const LeafNumbering numbering = leaf_numbering(imported.hierarchy, mesh, imported.vertex_of_input);
                  EncodeOptions options;
                  options.quantize_bits = quantize;
                  options.numbering = &numbering;
                  options.store_numbering = keep_numbering;
                  data = encode(imported.hierarchy, options, &stats);
              }
              if (!return_stats) return to_bytes(data);
              py::dict map;
              map["vertex"] = vector_array(stats.numbering.vertex);
              map["face"] = vector_array(stats.numbering.face);
              map["rotation"] = vector_array(stats.numbering.rotation);
              py::dict s = stats_dict(stats);
              s["numbering"] = map;
              return py::make_tuple(to_bytes(data), s);
          },
          py::arg("points"), py::arg("triangles"), py::arg("base") = py::none(), py::arg("keep_numbering") = false,
          py::arg("quantize") = 0, py::arg("return_stats") = false,
          "Compresses a triangle mesh to .amc bytes. The mesh is imported over `base` (a (points, triangles) pair) or\n"
          "over the coarsest base found in it. keep_numbering stores the mesh's own vertex and face numbering, so\n"
          "that decode returns it; return_stats also returns a dict of sizes and the numbering map.");

    m.def("decode", [](py::bytes data, int level, bool canonical) {
              const std::string bytes = data;
              LeafNumbering numbering;
              Hierarchy h;
              {
                  py::gil_scoped_release release;
                  DecodeOptions options;
                  options.max_level = level;
                  h = decode(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), options, &numbering);
              }
              const LeafMesh leaf = extract_leaf_mesh(h, level);
              if (!numbering.empty() && !canonical) {
                  CellData cells;
                  const TriangleMesh mesh = renumber_leaf_mesh(leaf, numbering, &cells);
                  return mesh_dict(mesh, cells, &numbering);
              }
              return mesh_dict(leaf.mesh, leaf.cells, &numbering);
          },
          py::arg("data"), py::arg("level") = -1, py::arg("canonical") = false,
          "Decodes .amc bytes to a dict: points, triangles, level and green per triangle, and numbering (the stored\n"
          "map from the input's numbering to the canonical one, or None). The mesh is in the input's numbering\n"
          "when the file stores it, unless canonical=True; level cuts the decoding at that level.");

    m.def("decode_hierarchy", [](py::bytes data) {
              const std::string bytes = data;
              py::gil_scoped_release release;
              return decode(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
          },
          py::arg("data"), "Decodes .amc bytes to a Hierarchy.");

    m.def("import_mesh", [](const py::array& points, const py::array& triangles, const py::object& base) {
              ImportedHierarchy imported = import_arrays(mesh_from_arrays(points, triangles, "mesh"), base);
              return py::make_tuple(std::move(imported.hierarchy), vector_array(imported.vertex_of_input));
          },
          py::arg("points"), py::arg("triangles"), py::arg("base") = py::none(),
          "A mesh as a Hierarchy (over `base` or the coarsest base found) and, per input vertex, its hierarchy vertex id.");

    m.attr("__version__") = AMC_VERSION;
}
