// Writes tests/data/vtu/dune_*.vtu with DUNE's own VTKWriter (Debian's libdune-grid-dev, UGGrid):
// a 2 x 2 grid of 8 triangles on [0,1] x [0,0.5], point data "height" (10 x + y) and cell data
// "index" (element index + 0.5), in the four output types DUNE has: ascii, inline base64,
// appended raw and appended base64. Built and run by scripts/make_vtu_fixtures.py.
#include <config.h>

#include <string>
#include <vector>

#include <dune/common/parallel/mpihelper.hh>
#include <dune/geometry/type.hh>
#include <dune/grid/common/gridfactory.hh>
#include <dune/grid/io/file/vtk/vtkwriter.hh>
#include <dune/grid/uggrid.hh>

int main(int argc, char** argv) {
    Dune::MPIHelper::instance(argc, argv);
    const std::string dir = argc > 1 ? argv[1] : ".";
    using Grid = Dune::UGGrid<2>;
    Dune::GridFactory<Grid> factory;
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) factory.insertVertex({0.5 * i, 0.25 * j});
    }
    for (unsigned j = 0; j < 2; ++j) {
        for (unsigned i = 0; i < 2; ++i) {
            const unsigned a = 3 * j + i, b = a + 1, c = a + 3, d = c + 1;
            factory.insertElement(Dune::GeometryTypes::triangle, {a, b, d});
            factory.insertElement(Dune::GeometryTypes::triangle, {a, d, c});
        }
    }
    auto grid = factory.createGrid();
    auto view = grid->leafGridView();
    const auto& indices = view.indexSet();
    std::vector<double> height(view.size(2)), index(view.size(0));
    for (const auto& v : vertices(view)) {
        const auto x = v.geometry().center();
        height[indices.index(v)] = 10 * x[0] + x[1];
    }
    for (const auto& e : elements(view)) index[indices.index(e)] = indices.index(e) + 0.5;
    const struct {
        Dune::VTK::OutputType type;
        const char* name;
    } outputs[] = {{Dune::VTK::ascii, "dune_ascii"},
                   {Dune::VTK::base64, "dune_base64"},
                   {Dune::VTK::appendedraw, "dune_appended_raw"},
                   {Dune::VTK::appendedbase64, "dune_appended_base64"}};
    for (const auto& output : outputs) {
        Dune::VTKWriter<decltype(view)> writer(view);
        writer.addVertexData(height, "height");
        writer.addCellData(index, "index");
        writer.write(dir + "/" + output.name, output.type);
    }
}
