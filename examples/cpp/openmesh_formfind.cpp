// Voussoir with OpenMesh: `openmesh_formfind input.obj output.off` reads a triangle mesh (OBJ,
// OFF, PLY, STL), form finds it on its lowest border vertices and writes it. Exit status: 0
// converged, 1 stopped otherwise, 2 on errors.
#include <voussoir/openmesh.hpp>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <algorithm>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <vector>

using TriMesh = OpenMesh::TriMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;

int main(int argc, char **argv) try {
    TriMesh om;
    if (argc != 3) throw std::invalid_argument("usage: openmesh_formfind input.obj output.off");
    if (!OpenMesh::IO::read_mesh(om, argv[1]))
        throw std::runtime_error(std::string("cannot read ") + argv[1]);
    double low = std::numeric_limits<double>::infinity();
    for (auto v : om.vertices()) low = std::min(low, om.point(v)[2]);
    std::vector<OpenMesh::VertexHandle> supports;
    for (auto v : om.vertices())
        if (om.is_boundary(v) && om.point(v)[2] <= low + 1e-9) supports.push_back(v);
    const voussoir::Result result = voussoir::form_find(voussoir::openmesh::to_mesh(om, supports));
    voussoir::openmesh::set_positions(result, om);
    const auto q = voussoir::openmesh::add_force_densities(result, om);
    double q_max = 0;  // the force densities are an edge property now
    for (auto e : om.edges()) q_max = std::max(q_max, om.property(q, e));
    if (!OpenMesh::IO::write_mesh(om, argv[2], OpenMesh::IO::Options::Default, 17))
        throw std::runtime_error(std::string("cannot write ") + argv[2]);
    std::cout << result.termination_message() << "; largest force density " << q_max << "\n";
    return result.termination().converged() ? 0 : 1;
} catch (const std::exception &e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
}
