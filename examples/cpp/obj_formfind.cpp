// Voussoir from C++: an OBJ read with OpenMesh, form found, written back.
//
//   obj_formfind input.obj output.obj [supports.json]
//
// Supports are the ids listed in the JSON sidecar's "anchored" array (0-based, as in
// ../shared/data/models/*.json) or, without one, the boundary vertices at the lowest height.
// The output has the same vertices and faces as OpenMesh read them, with the form-found
// heights. Exit status: 0 when form finding converged, 1 when it stopped otherwise, 2 on
// errors.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <voussoir.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

// Double-precision points: the form-found heights balance to ~1e-7 of the load, which single
// precision (OpenMesh's default Vec3f) would destroy.
struct DoubleTraits : public OpenMesh::DefaultTraits {
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
};
using Mesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

// OpenMesh 9's OBJ writer prints single precision even for double points, so the result is
// written here with 17 significant digits (faces as OpenMesh holds them).
static bool write_obj(const Mesh &mesh, const char *path) {
    std::ofstream out(path);
    out.precision(17);
    for (auto v : mesh.vertices()) {
        const auto &p = mesh.point(v);
        out << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    }
    for (auto f : mesh.faces()) {
        out << 'f';
        for (auto v : mesh.fv_range(f)) out << ' ' << v.idx() + 1;
        out << '\n';
    }
    return static_cast<bool>(out);
}

namespace {

// Owning wrappers: the handles are freed on every path out.
struct MeshDeleter {
    void operator()(VsrMesh *m) const { vsr_mesh_destroy(m); }
};
struct SettingsDeleter {
    void operator()(VsrSettings *s) const { vsr_settings_destroy(s); }
};
struct ResultDeleter {
    void operator()(VsrResult *r) const { vsr_result_destroy(r); }
};

void check(VsrStatus status, const char *what) {
    if (status != VSR_STATUS_OK)
        throw std::runtime_error(std::string(what) + ": " + vsr_status_name(status) + ": " +
                                 vsr_last_error_message());
}

// The numbers of the "anchored": [ ... ] array of a JSON file (enough for the sidecars).
std::vector<uint32_t> read_anchored(const std::string &path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read " + path);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    const auto key = text.find("\"anchored\"");
    const auto open = key == std::string::npos ? key : text.find('[', key);
    const auto close = open == std::string::npos ? open : text.find(']', open);
    if (close == std::string::npos) throw std::runtime_error(path + ": no \"anchored\" array");
    std::vector<uint32_t> ids;
    std::stringstream list(text.substr(open + 1, close - open - 1));
    std::string item;
    while (std::getline(list, item, ','))
        if (item.find_first_not_of(" \t\r\n") != std::string::npos)
            ids.push_back(static_cast<uint32_t>(std::stoul(item)));
    return ids;
}

std::vector<uint32_t> lowest_boundary(const Mesh &mesh) {
    double lo = INFINITY, hi = -INFINITY;
    for (auto v : mesh.vertices()) {
        lo = std::min<double>(lo, mesh.point(v)[2]);
        hi = std::max<double>(hi, mesh.point(v)[2]);
    }
    std::vector<uint32_t> ids;
    for (auto v : mesh.vertices())
        if (mesh.is_boundary(v) && mesh.point(v)[2] <= lo + 1e-9 * std::max(1.0, hi - lo))
            ids.push_back(static_cast<uint32_t>(v.idx()));
    return ids;
}

int run(int argc, char **argv) {
    if (argc < 3) {
        std::cerr << "usage: " << argv[0] << " input.obj output.obj [supports.json]\n";
        return 2;
    }
    Mesh mesh;
    if (!OpenMesh::IO::read_mesh(mesh, argv[1]))
        throw std::runtime_error(std::string("OpenMesh cannot read ") + argv[1]);

    std::vector<double> positions;
    positions.reserve(3 * mesh.n_vertices());
    for (auto v : mesh.vertices())
        for (int c = 0; c < 3; ++c) positions.push_back(mesh.point(v)[c]);
    std::vector<uint32_t> triangles;
    triangles.reserve(3 * mesh.n_faces());
    for (auto f : mesh.faces())
        for (auto v : mesh.fv_range(f)) triangles.push_back(static_cast<uint32_t>(v.idx()));
    const std::vector<uint32_t> anchored =
        argc > 3 ? read_anchored(argv[3]) : lowest_boundary(mesh);
    std::cout << argv[1] << ": " << mesh.n_vertices() << " vertices, " << mesh.n_faces()
              << " faces, " << anchored.size() << " supports\n";

    VsrMesh *raw_mesh = nullptr;
    check(vsr_mesh_create(positions.data(), mesh.n_vertices(), triangles.data(), mesh.n_faces(),
                          anchored.data(), anchored.size(), &raw_mesh),
          "vsr_mesh_create");
    std::unique_ptr<VsrMesh, MeshDeleter> vmesh(raw_mesh);

    VsrSettings *raw_settings = nullptr;
    check(vsr_settings_create(&raw_settings), "vsr_settings_create");
    std::unique_ptr<VsrSettings, SettingsDeleter> settings(raw_settings);
    check(vsr_settings_set_max_iterations(settings.get(), 100), "vsr_settings_set_max_iterations");

    VsrResult *raw_result = nullptr;
    check(vsr_form_find(vmesh.get(), settings.get(), &raw_result), "vsr_form_find");
    std::unique_ptr<VsrResult, ResultDeleter> result(raw_result);

    // Copy-out with a size query first.
    size_t needed = 0;
    check(vsr_result_positions(result.get(), nullptr, 0, &needed), "vsr_result_positions");
    std::vector<double> found(needed);
    check(vsr_result_positions(result.get(), found.data(), found.size(), &needed),
          "vsr_result_positions");
    for (auto v : mesh.vertices()) {
        const size_t i = static_cast<size_t>(v.idx());
        mesh.set_point(v, Mesh::Point(found[3 * i], found[3 * i + 1], found[3 * i + 2]));
    }
    if (!write_obj(mesh, argv[2]))
        throw std::runtime_error(std::string("OpenMesh cannot write ") + argv[2]);

    VsrTermination termination;
    size_t iterations = 0;
    check(vsr_result_termination(result.get(), &termination, &iterations),
          "vsr_result_termination");
    VsrStressStatus stress;
    double eps_inf = 0, objective = 0, hausdorff = 0, l2 = 0;
    size_t qp_iterations = 0;
    check(vsr_result_stress_summary(result.get(), &stress, &eps_inf, &objective, &qp_iterations),
          "vsr_result_stress_summary");
    check(vsr_result_distances(result.get(), &hausdorff, &l2), "vsr_result_distances");
    check(vsr_result_termination_message(result.get(), nullptr, 0, &needed),
          "vsr_result_termination_message");
    std::string message(needed, '\0');
    check(vsr_result_termination_message(result.get(), &message[0], message.size(), &needed),
          "vsr_result_termination_message");
    message.resize(needed - 1);

    std::printf("%s after %zu iterations: eps_inf = %.3e, moved by at most %.3e of the plan "
                "diagonal\nwrote %s\n",
                message.c_str(), iterations, eps_inf, hausdorff, argv[2]);
    return termination == VSR_TERMINATION_CONVERGED ? 0 : 1;
}

}  // namespace

int main(int argc, char **argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception &e) {
        std::cerr << "error: " << e.what() << "\n";
        return 2;
    }
}
