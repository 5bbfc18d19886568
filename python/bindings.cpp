// The Python module amcodec._amcodec: numpy arrays in and out of the public C++ API. Errors are
// raised as amcodec.Error with the library's message. A call releases the GIL only while it works
// on its own copies: one that reads or changes a Hierarchy, reader or writer that other Python
// threads can reach holds it (the library's calls are not safe against a concurrent change).
#include <amc/codec.h>
#include <amc/hierarchy.h>
#include <amc/import.h>
#include <amc/numbering.h>
#include <amc/series.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <type_traits>
#include <variant>
#include <string>

namespace py = pybind11;
using namespace amc;

namespace {

using PointArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// The triangles' vertex indices: an integer array, or a float one whose values are all integers
// (as np.loadtxt gives); a fraction would otherwise be truncated to another vertex without a word.
std::vector<Triangle> triangles_from_array(const py::array& triangles, size_t vertex_count, const char* what) {
    const char kind = triangles.dtype().kind();
    if (triangles.ndim() != 2 || triangles.shape(1) != 3 || (kind != 'i' && kind != 'u' && kind != 'f'))
        throw Error(std::string(what) + ": triangles must be an (m, 3) integer array");
    std::vector<Triangle> out(size_t(triangles.shape(0)));
    auto refuse = [&](py::ssize_t i, const std::string& shown, const char* why) {
        throw Error(std::string(what) + ": triangle " + std::to_string(i) + " has vertex index " + shown + why);
    };
    auto shown = [](auto v) -> std::string {
        if constexpr (std::is_floating_point_v<decltype(v)>) return py::str(py::float_(v));
        else return std::to_string(v);
    };
    auto take = [&](const auto& t) {
        auto tv = t.template unchecked<2>();
        for (py::ssize_t i = 0; i < t.shape(0); ++i) {
            for (int c = 0; c < 3; ++c) {
                const auto v = tv(i, c);
                if constexpr (std::is_floating_point_v<decltype(v)>)
                    if (v != std::floor(v)) refuse(i, shown(v), ", not an integer");  // a fraction, or NaN
                if (!(v >= 0 && v < decltype(v)(vertex_count))) refuse(i, shown(v), " out of range");
                out[size_t(i)][c] = uint32_t(v);
            }
        }
    };
    if (kind == 'f')
        take(py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(triangles));
    else if (kind == 'u')
        take(py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(triangles));
    else
        take(py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(triangles));
    return out;
}

// A numpy (n, 3) array of coordinates, or (n, 2) for a planar mesh (z = 0, as meshio and FE codes
// hand 2-D meshes); float32 input keeps single precision (bit-exact files).
TriangleMesh mesh_from_arrays(const py::array& points, const py::array& triangles, const char* what) {
    TriangleMesh mesh;
    mesh.single_precision = points.dtype().is(py::dtype::of<float>());
    const PointArray p = PointArray::ensure(points);
    if (!p || p.ndim() != 2 || (p.shape(1) != 3 && p.shape(1) != 2))
        throw Error(std::string(what) + ": points must be an (n, 3) or (n, 2) array");
    auto pv = p.unchecked<2>();
    const bool planar = p.shape(1) == 2;
    mesh.positions.resize(size_t(p.shape(0)));
    for (py::ssize_t i = 0; i < p.shape(0); ++i) mesh.positions[size_t(i)] = {pv(i, 0), pv(i, 1), planar ? 0.0 : pv(i, 2)};
    mesh.triangles = triangles_from_array(triangles, mesh.positions.size(), what);
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

// `base_map` (or None): per base vertex, the index of its vertex in `mesh` (instead of matching
// them by position), as import_leaf_mesh takes it.
ImportedHierarchy import_arrays(const TriangleMesh& mesh, const py::object& base, const py::object& base_map) {
    if (base.is_none()) {
        if (!base_map.is_none()) throw Error("base_map: given without a base");
        py::gil_scoped_release release;
        return import_mesh(mesh, "mesh");
    }
    const py::tuple pair = base.cast<py::tuple>();
    if (pair.size() != 2) throw Error("base: expected a (points, triangles) pair");
    const TriangleMesh base_mesh = mesh_from_arrays(pair[0].cast<py::array>(), pair[1].cast<py::array>(), "base mesh");
    std::vector<uint32_t> map;
    if (!base_map.is_none()) {
        const py::array a = py::array::ensure(base_map);
        const char kind = a ? a.dtype().kind() : 'O';
        if (!a || a.ndim() != 1 || (kind != 'i' && kind != 'u')) throw Error("base_map: expected an (n,) integer array");
        const auto values = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        auto v = values.unchecked<1>();
        for (py::ssize_t i = 0; i < values.shape(0); ++i) {
            if (v(i) < 0 || v(i) > int64_t(UINT32_MAX))
                throw Error("base_map: base vertex " + std::to_string(i) + " maps to " + std::to_string(v(i)) + ", not a vertex");
            map.push_back(uint32_t(v(i)));
        }
    }
    py::gil_scoped_release release;
    return import_leaf_mesh(base_mesh, mesh, map, "mesh");
}

// amcodec.info: what inspect() reads of a file, as amc info prints it.
py::dict info_dict(const FileInfo& info) {
    py::dict d;
    d["version"] = info.version;
    d["single_precision"] = info.single_precision;
    d["quantize_bits"] = info.quantize_bits;
    d["base_vertices"] = info.base_vertices;
    d["base_triangles"] = info.base_triangles;
    d["nodes"] = info.nodes;
    d["vertices"] = info.vertices;
    d["faces"] = info.faces;
    d["levels"] = info.levels;
    py::list blocks, chunks;
    for (const FileBlock& b : info.blocks) {
        py::dict block;
        block["name"] = b.name;
        block["offset"] = b.offset;
        block["bytes"] = b.size;
        block["level"] = b.level >= 0 ? py::object(py::int_(b.level)) : py::object(py::none());
        blocks.append(block);
    }
    for (const ChunkInfo& c : info.chunks) {
        py::dict chunk;
        chunk["first_root"] = c.first_root;
        chunk["roots"] = c.roots;
        chunk["nodes"] = c.nodes;
        chunk["offset"] = c.offset;
        chunk["bytes"] = c.size;
        chunks.append(chunk);
    }
    d["blocks"] = blocks;
    d["chunks"] = chunks;
    return d;
}

// The library reads a node id unchecked: one from Python is looked up first.
NodeId existing_node(const Hierarchy& h, NodeId n, const char* what) {
    if (!h.is_alive(n)) throw Error(std::string(what) + ": no node " + std::to_string(n));
    return n;
}

// A vertex id from Python, checked against the hierarchy's ids.
VertexId existing_vertex(const Hierarchy& h, VertexId v, const char* what) {
    if (v >= h.positions().size()) throw Error(std::string(what) + ": no vertex " + std::to_string(v));
    return v;
}

py::object node_or_none(NodeId n) { return n == kNoNode ? py::object(py::none()) : py::object(py::int_(n)); }

py::array_t<double> vec3_array(Vec3 p) {
    py::array_t<double> out(3);
    auto o = out.mutable_unchecked<1>();
    o(0) = p.x, o(1) = p.y, o(2) = p.z;
    return out;
}

// Hierarchy.leaf_mesh: the mesh with, per triangle, the node it belongs to and, per point, its
// hierarchy vertex id, which tie the mesh to the nodes and vertices the other methods name.
py::dict leaf_dict(const Hierarchy& h, int level) {
    const LeafMesh leaf = extract_leaf_mesh(h, level);
    py::dict d = mesh_dict(leaf.mesh, leaf.cells, nullptr);
    d.attr("pop")("numbering");
    d["node"] = vector_array(leaf.source);
    const std::vector<uint32_t> canonical = canonical_vertex_order(h);
    std::vector<uint32_t> vertex_of_point(leaf.mesh.positions.size(), kNoVertex);
    for (VertexId v = 0; v < canonical.size(); ++v)
        if (canonical[v] < vertex_of_point.size()) vertex_of_point[canonical[v]] = v;
    d["vertex"] = vector_array(vertex_of_point);
    return d;
}

py::bytes to_bytes(const std::vector<uint8_t>& data) { return py::bytes(reinterpret_cast<const char*>(data.data()), data.size()); }

// ---- series (.amcs): fields as numpy arrays, (n,) or (n, components), of the field's own type ----

template <class T>
DataArray data_array_of(const std::string& name, const py::array& a) {
    const auto typed = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(a);
    DataArray out;
    out.name = name;
    out.components = a.ndim() == 2 ? uint32_t(a.shape(1)) : 1;
    out.values = std::vector<T>(typed.data(), typed.data() + typed.size());
    return out;
}

DataArray data_array_of(const std::string& name, const py::array& a) {
    if (a.ndim() < 1 || a.ndim() > 2 || (a.ndim() == 2 && a.shape(1) < 1))
        throw Error("field \"" + name + "\": expected an (n,) or (n, components) array");
    const char kind = a.dtype().kind();
    const size_t size = size_t(a.dtype().itemsize());
    if (kind == 'f' && size == 4) return data_array_of<float>(name, a);
    if (kind == 'f' && size == 8) return data_array_of<double>(name, a);
    if (kind == 'i' && size == 1) return data_array_of<int8_t>(name, a);
    if (kind == 'i' && size == 2) return data_array_of<int16_t>(name, a);
    if (kind == 'i' && size == 4) return data_array_of<int32_t>(name, a);
    if (kind == 'i' && size == 8) return data_array_of<int64_t>(name, a);
    if ((kind == 'u' || kind == 'b') && size == 1) return data_array_of<uint8_t>(name, a);
    if (kind == 'u' && size == 2) return data_array_of<uint16_t>(name, a);
    if (kind == 'u' && size == 4) return data_array_of<uint32_t>(name, a);
    if (kind == 'u' && size == 8) return data_array_of<uint64_t>(name, a);
    throw Error("field \"" + name + "\": unsupported dtype " + std::string(py::str(a.dtype())));
}

std::vector<DataArray> data_arrays_of(const py::dict& arrays) {
    std::vector<DataArray> out;
    for (const auto& [name, value] : arrays) out.push_back(data_array_of(py::str(name), py::array::ensure(value)));
    return out;
}

py::array array_of(const DataArray& a) {
    return std::visit(
        [&](const auto& values) -> py::array {
            using T = typename std::decay_t<decltype(values)>::value_type;
            const size_t tuples = a.components == 0 ? 0 : values.size() / a.components;
            py::array_t<T> out = a.components == 1 ? py::array_t<T>(py::ssize_t(tuples))
                                                   : py::array_t<T>({py::ssize_t(tuples), py::ssize_t(a.components)});
            if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
            return std::move(out);
        },
        a.values);
}

// A decoded frame: its leaf mesh (canonical numbering) with level and green, its time, and its
// fields as point_data and cell_data dicts.
py::dict frame_dict(const SeriesFrame& frame) {
    const LeafMesh leaf = extract_leaf_mesh(frame.hierarchy);
    py::dict d = mesh_dict(leaf.mesh, leaf.cells, nullptr);
    d.attr("pop")("numbering");
    d["time"] = frame.time;
    py::dict point_data, cell_data;
    for (const Field& f : frame.fields)
        (f.association == FieldAssociation::point ? point_data : cell_data)[py::str(f.name)] = array_of(array_from_field(f));
    d["point_data"] = point_data;
    d["cell_data"] = cell_data;
    return d;
}

py::dict frame_stats_dict(const SeriesFrameStats& s) {
    py::dict d;
    d["keyframe"] = s.keyframe;
    d["bytes"] = s.bytes;
    d["connectivity_bytes"] = s.connectivity_bytes;
    d["geometry_bytes"] = s.geometry_bytes;
    d["field_bytes"] = s.field_bytes;
    d["nodes"] = s.nodes;
    d["vertices"] = s.vertices;
    d["faces"] = s.faces;
    d["changed_nodes"] = s.changed_nodes;
    d["max_error"] = s.max_error;
    return d;
}

// The writer as Python sees it: in memory (bytes()) or appending to a file (path).
struct PySeriesWriter {
    std::unique_ptr<SeriesWriter> writer;
    TriangleMesh base;
};

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
        .def("is_leaf", [](const Hierarchy& h, NodeId n) { return h.is_leaf(existing_node(h, n, "is_leaf")); }, py::arg("node"))
        .def("level", [](const Hierarchy& h, NodeId n) { return h.level(existing_node(h, n, "level")); }, py::arg("node"))
        .def("leaves", &Hierarchy::leaves, "Leaf node ids in breadth-first order.")
        .def("refine", [](Hierarchy& h, NodeId n) {
                 return h.refine(existing_node(h, n, "refine"));
             }, py::arg("node"), "Red-refines a leaf with balance and closure; returns the number of nodes split.")
        .def("coarsen", [](Hierarchy& h, NodeId n) {
                 return h.coarsen(existing_node(h, n, "coarsen"));
             }, py::arg("node"), "Removes a node's four leaf children where balance allows; returns whether it did.")
        .def("check", &check_invariants, "Every structural invariant: '' if valid, else the first violation.")
        .def("leaf_mesh", &leaf_dict, py::arg("level") = -1,
             "The conforming leaf mesh (or the mesh of one level, its nodes as leaves): dict with points, triangles,\n"
             "level and green per triangle, node (the node each triangle belongs to) and vertex (each point's vertex id).")
        .def_property_readonly("node_capacity", &Hierarchy::node_capacity,
                               "Node ids are below it (roots first: 0 .. root_count - 1); removed nodes' ids are reused.")
        .def("is_alive", &Hierarchy::is_alive, py::arg("node"), "Whether the id names a node (not removed).")
        .def("parent", [](const Hierarchy& h, NodeId n) { return node_or_none(h.parent(existing_node(h, n, "parent"))); },
             py::arg("node"), "The parent node, None for a root.")
        .def("children", [](const Hierarchy& h, NodeId n) {
                 py::list out;
                 if (!h.is_leaf(existing_node(h, n, "children")))
                     for (int k = 0; k < 4; ++k) out.append(h.child(n, k));
                 return out;
             }, py::arg("node"), "The four children (three corners, then the center; docs/HIERARCHY.md), [] for a leaf.")
        .def("vertices", [](const Hierarchy& h, NodeId n) {
                 existing_node(h, n, "vertices");
                 return py::make_tuple(h.vertex(n, 0), h.vertex(n, 1), h.vertex(n, 2));
             }, py::arg("node"), "The node's three corner vertex ids, in its orientation (the base triangle's, for every node of its tree).")
        .def("neighbors", [](const Hierarchy& h, NodeId n) {
                 existing_node(h, n, "neighbors");
                 return py::make_tuple(node_or_none(h.neighbor(n, 0)), node_or_none(h.neighbor(n, 1)), node_or_none(h.neighbor(n, 2)));
             }, py::arg("node"),
             "The same-level neighbours across edges 0, 1, 2 (edge e from vertex e to vertex e + 1); None at the\n"
             "boundary or where the mesh there is coarser.")
        .def("position", [](const Hierarchy& h, VertexId v) { return vec3_array(h.position(existing_vertex(h, v, "position"))); },
             py::arg("vertex"), "The vertex's position, a (3,) array.")
        .def("set_position", [](Hierarchy& h, VertexId v, const PointArray& p) {
                 if (p.size() != 3) throw Error("set_position: expected three coordinates");
                 h.set_position(existing_vertex(h, v, "set_position"), {p.data()[0], p.data()[1], p.data()[2]});
             }, py::arg("vertex"), py::arg("point"), "Moves a vertex (checked when the hierarchy is encoded).")
        .def_property_readonly("base", [](const Hierarchy& h) {
                 return py::make_tuple(points_array(h.base()), triangles_array(h.base().triangles));
             }, "The base mesh: (points, triangles); base vertex i is vertex id i, base triangle t root node t.")
        .def("encode", [](const Hierarchy& h, int quantize, int effort, uint32_t chunks) {
                 EncodeOptions options;
                 options.quantize_bits = quantize;
                 options.effort = effort;
                 options.chunks = chunks;
                 return to_bytes(encode(h, options));
             }, py::arg("quantize") = 0, py::arg("effort") = kDefaultEffort, py::arg("chunks") = 0,
             "Compresses to .amc bytes (quantize: 0 bit-exact, else bits per axis; effort 0 to 4: how hard the\n"
             "encoder looks, as amc encode --effort; chunks: that many independently decodable runs of roots, as\n"
             "amc encode --chunks, 0: one per 500,000 faces).")
        .def("identical", [](const Hierarchy& a, const Hierarchy& b) { return identical(a, b); }, py::arg("other"),
             "Same base, forest, diagonals and bit-identical positions (canonical order).");

    m.def("encode", [](const py::array& points, const py::array& triangles, const py::object& base, bool keep_numbering,
                       int quantize, bool return_stats, int effort, const py::object& base_map) -> py::object {
              const TriangleMesh mesh = mesh_from_arrays(points, triangles, "mesh");
              ImportedHierarchy imported = import_arrays(mesh, base, base_map);
              EncodeStats stats;
              std::vector<uint8_t> data;
              {
                  py::gil_scoped_release release;
                  // Only when stored or returned: given one, the encoder takes a slower path.
                  LeafNumbering numbering;
                  EncodeOptions options;
                  options.quantize_bits = quantize;
                  options.effort = effort;
                  if (keep_numbering || return_stats) {
                      numbering = leaf_numbering(imported.hierarchy, mesh, imported.vertex_of_input);
                      options.numbering = &numbering;
                      options.store_numbering = keep_numbering;
                  }
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
          py::arg("quantize") = 0, py::arg("return_stats") = false, py::arg("effort") = kDefaultEffort,
          py::arg("base_map") = py::none(),
          "Compresses a triangle mesh to .amc bytes. The mesh is imported over `base` (a (points, triangles) pair) or\n"
          "over the coarsest base found in it. keep_numbering stores the mesh's own vertex and face numbering, so\n"
          "that decode returns it; return_stats also returns a dict of sizes and the numbering map; effort (0 to 4)\n"
          "as amc encode --effort; base_map: per base vertex the index of its vertex in the mesh (default: matched by\n"
          "position).");

    m.def("decode", [](py::bytes data, int level, bool canonical, bool partial) {
              const std::string bytes = data;
              LeafNumbering numbering;
              Hierarchy h;
              PartialDecode arrived;
              {
                  py::gil_scoped_release release;
                  DecodeOptions options;
                  options.max_level = level;
                  const auto* begin = reinterpret_cast<const uint8_t*>(bytes.data());
                  if (partial) {
                      arrived = decode_partial(begin, bytes.size(), options);
                      h = std::move(arrived.hierarchy);
                      numbering = std::move(arrived.numbering);
                  } else {
                      h = decode(begin, bytes.size(), options, &numbering);
                  }
              }
              const LeafMesh leaf = extract_leaf_mesh(h, level);
              py::dict result;
              if (!numbering.empty() && !canonical) {
                  CellData cells;
                  const TriangleMesh mesh = renumber_leaf_mesh(leaf, numbering, &cells);
                  result = mesh_dict(mesh, cells, &numbering);
              } else {
                  result = mesh_dict(leaf.mesh, leaf.cells, &numbering);
              }
              if (partial) {
                  result["complete"] = arrived.complete;
                  result["reached_level"] = arrived.level;
                  result["levels"] = arrived.levels;
              }
              return result;
          },
          py::arg("data"), py::arg("level") = -1, py::arg("canonical") = false, py::arg("partial") = false,
          "Decodes .amc bytes to a dict: points, triangles, level and green per triangle, and numbering (the stored\n"
          "map from the input's numbering to the canonical one, or None). The mesh is in the input's numbering\n"
          "when the file stores it, unless canonical=True; level cuts the decoding at that level. partial=True\n"
          "accepts a file still arriving (cut after its base mesh): the levels complete so far, with 'complete',\n"
          "'reached_level' and 'levels' in the dict.");

    m.def("info", [](py::bytes data) {
              const std::string bytes = data;
              return info_dict(inspect(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
          },
          py::arg("data"),
          "What an .amc file holds, without decoding it (as amc info): version, precision, counts, levels, its\n"
          "blocks (name, offset, bytes, level) and chunks (first_root, roots, nodes, offset, bytes; [] without chunks).");

    m.def("decode_chunks", [](py::bytes data, const std::vector<uint32_t>& chunks) {
              const std::string bytes = data;
              ChunkDecode part;
              {
                  py::gil_scoped_release release;
                  part = decode_chunks(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), chunks);
              }
              return py::make_tuple(std::move(part.hierarchy), vector_array(part.roots), vector_array(part.base_vertices));
          },
          py::arg("data"), py::arg("chunks"),
          "Some chunks of a chunked file alone (indices into info(data)['chunks'], increasing; a file without chunks\n"
          "has chunk 0): (Hierarchy over their roots, the file's root of each of its roots, the file's base vertex of\n"
          "each of its base vertices).");

    m.def("decode_hierarchy", [](py::bytes data) {
              const std::string bytes = data;
              py::gil_scoped_release release;
              return decode(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
          },
          py::arg("data"), "Decodes .amc bytes to a Hierarchy.");

    m.def("import_mesh", [](const py::array& points, const py::array& triangles, const py::object& base, const py::object& base_map) {
              ImportedHierarchy imported = import_arrays(mesh_from_arrays(points, triangles, "mesh"), base, base_map);
              return py::make_tuple(std::move(imported.hierarchy), vector_array(imported.vertex_of_input));
          },
          py::arg("points"), py::arg("triangles"), py::arg("base") = py::none(), py::arg("base_map") = py::none(),
          "A mesh as a Hierarchy (over `base` or the coarsest base found; base_map as for encode) and, per input\n"
          "vertex, its hierarchy vertex id.");

    py::class_<PySeriesWriter>(m, "SeriesWriter",
                               "Writes a series (.amcs) frame by frame: in memory (bytes()) or appended to `path` as each\n"
                               "frame is added, so that a reader sees every complete frame even if the writer dies.")
        .def(py::init([](const py::array& base_points, const py::array& base_triangles, const py::object& path,
                         uint32_t keyframe_interval, double error_bound, const py::dict& field_bounds) {
                 SeriesOptions options;
                 options.keyframe_interval = keyframe_interval;
                 options.error_bound = error_bound;
                 for (const auto& [name, bound] : field_bounds) options.field_bounds.push_back({py::str(name), bound.cast<double>()});
                 auto w = std::make_unique<PySeriesWriter>();
                 w->base = mesh_from_arrays(base_points, base_triangles, "base");
                 w->writer = path.is_none() ? std::make_unique<SeriesWriter>(w->base, options)
                                            : std::make_unique<SeriesWriter>(path.cast<std::string>(), w->base, options);
                 return w;
             }),
             py::arg("base_points"), py::arg("base_triangles"), py::arg("path") = py::none(), py::arg("keyframe_interval") = 0,
             py::arg("error_bound") = 0.0, py::arg("field_bounds") = py::dict(),
             "base: the mesh every frame refines. keyframe_interval K: frames 0, K, 2K... decode on their own.\n"
             "error_bound: absolute bound of every float field (0: bit-exact); field_bounds: {name: bound}.")
        .def("add_frame", [](PySeriesWriter& w, const Hierarchy& h, double time, const py::dict& point_data, const py::dict& cell_data) {
                 std::vector<Field> fields;
                 for (const DataArray& a : data_arrays_of(point_data)) fields.push_back(field_from_array(a, FieldAssociation::point));
                 for (const DataArray& a : data_arrays_of(cell_data)) fields.push_back(field_from_array(a, FieldAssociation::cell));
                 return frame_stats_dict(w.writer->add_frame(h, time, fields));
             },
             py::arg("hierarchy"), py::arg("time") = 0.0, py::arg("point_data") = py::dict(), py::arg("cell_data") = py::dict(),
             "Adds a Hierarchy over the base; point_data arrays follow its leaf mesh's vertices (canonical order), cell_data\n"
             "its triangles. Returns the frame's sizes.")
        .def("add_mesh", [](PySeriesWriter& w, const py::array& points, const py::array& triangles, double time,
                            const py::dict& point_data, const py::dict& cell_data) {
                 VtuMesh vtu;
                 vtu.mesh = mesh_from_arrays(points, triangles, "frame");
                 vtu.point_data = data_arrays_of(point_data);
                 vtu.cell_data = data_arrays_of(cell_data);
                 const std::string name = "frame " + std::to_string(w.writer->frame_count());
                 SeriesFrame frame;
                 {
                     py::gil_scoped_release release;  // the import reads only copies and the base, set once
                     frame = frame_from_vtu(w.base, vtu, time, name);
                 }
                 return frame_stats_dict(w.writer->add_frame(frame.hierarchy, frame.time, frame.fields));
             },
             py::arg("points"), py::arg("triangles"), py::arg("time") = 0.0, py::arg("point_data") = py::dict(),
             py::arg("cell_data") = py::dict(),
             "Adds a leaf mesh over the base in any numbering, with its point and cell data in that numbering (a solver's\n"
             "output step). The reader returns it in canonical numbering.")
        .def("close", [](PySeriesWriter& w) { w.writer->close(); }, "Writes the END block (and closes the file).")
        .def("bytes", [](const PySeriesWriter& w) { return to_bytes(w.writer->bytes()); }, "The series so far (in memory).")
        .def("__len__", [](const PySeriesWriter& w) { return w.writer->frame_count(); });

    py::class_<SeriesReader>(m, "SeriesReader",
                             "Reads a series (.amcs); frame(k) decodes from the last keyframe at or before k.")
        .def(py::init([](py::bytes data, bool partial) {
                 const std::string bytes = data;
                 SeriesReadOptions options;
                 options.allow_unfinished = partial;
                 return SeriesReader(std::vector<uint8_t>(bytes.begin(), bytes.end()), "series", options);
             }),
             py::arg("data"), py::arg("partial") = false,
             "data: the bytes of an .amcs file. partial: read the complete frames of a file still being written.")
        .def_static("open", [](const std::string& path, bool partial) {
                 SeriesReadOptions options;
                 options.allow_unfinished = partial;
                 return SeriesReader::open(path, options);
             }, py::arg("path"), py::arg("partial") = false, "Reads an .amcs file.")
        .def("__len__", &SeriesReader::frame_count)
        .def("frame", [](SeriesReader& r, int64_t k) {
                 if (k < 0) k += int64_t(r.frame_count());
                 if (k < 0 || uint64_t(k) >= r.frame_count())
                     throw py::index_error("frame " + std::to_string(k) + " of " + std::to_string(r.frame_count()));
                 return frame_dict(r.frame(size_t(k)));
             }, py::arg("k"),
             "Frame k as a dict: points, triangles, level, green (canonical numbering), time, point_data, cell_data.")
        .def("hierarchy", [](SeriesReader& r, size_t k) {
                 if (k >= r.frame_count()) throw py::index_error("frame " + std::to_string(k) + " of " + std::to_string(r.frame_count()));
                 return r.frame(k).hierarchy;
             }, py::arg("k"), "Frame k's Hierarchy.")
        .def("info", [](const SeriesReader& r, size_t k) {
                 if (k >= r.frame_count()) throw py::index_error("frame " + std::to_string(k) + " of " + std::to_string(r.frame_count()));
                 const SeriesFrameInfo& f = r.info(k);
                 py::dict d;
                 d["offset"] = f.offset;
                 d["bytes"] = f.size;
                 d["keyframe"] = f.keyframe;
                 d["time"] = f.time;
                 d["nodes"] = f.nodes;
                 d["vertices"] = f.vertices;
                 d["faces"] = f.faces;
                 d["levels"] = f.levels;
                 return d;
             }, py::arg("k"), "Frame k's place and counts, without decoding it.")
        .def_property_readonly("finished", &SeriesReader::finished, "The END block is there.")
        .def_property_readonly("keyframe_interval", &SeriesReader::keyframe_interval)
        .def_property_readonly("base", [](const SeriesReader& r) {
            return py::make_tuple(points_array(r.base()), triangles_array(r.base().triangles));
        }, "The base mesh: (points, triangles).");

    m.attr("__version__") = AMC_VERSION;
}
