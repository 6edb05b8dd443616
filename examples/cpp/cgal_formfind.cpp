// Voussoir with CGAL: `cgal_formfind input.off output.off` reads a surface mesh (OFF; OBJ, PLY,
// STL too), form finds it on its lowest border vertices and writes it as OFF. Exit status: 0
// converged, 1 stopped otherwise, 2 on errors.
#include <voussoir/cgal.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

#include <algorithm>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <vector>

using Surface = CGAL::Surface_mesh<CGAL::Exact_predicates_inexact_constructions_kernel::Point_3>;

int main(int argc, char **argv) try {
    Surface sm;
    if (argc != 3) throw std::invalid_argument("usage: cgal_formfind input.off output.off");
    if (!CGAL::IO::read_polygon_mesh(argv[1], sm))
        throw std::runtime_error(std::string("cannot read ") + argv[1]);
    double low = std::numeric_limits<double>::infinity();
    for (auto v : sm.vertices()) low = std::min(low, sm.point(v).z());
    std::vector<Surface::Vertex_index> supports;
    for (auto v : sm.vertices())
        if (sm.is_border(v) && sm.point(v).z() <= low + 1e-9) supports.push_back(v);

    const voussoir::Result result = voussoir::form_find(voussoir::cgal::to_mesh(sm, supports));
    voussoir::cgal::set_positions(result, sm);
    if (!CGAL::IO::write_polygon_mesh(argv[2], sm, CGAL::parameters::stream_precision(17)))
        throw std::runtime_error(std::string("cannot write ") + argv[2]);
    std::cout << result.termination_message() << "; wrote " << argv[2] << "\n";
    return result.termination().converged() ? 0 : 1;
} catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
}
