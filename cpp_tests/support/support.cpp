// Support code of the C++ tests (see support.hpp). The only translation unit that includes CGAL.
#include "support.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_face_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

namespace vsrt {

// =============================================================================================
// Solves through voussoir.hpp

voussoir::Mesh make_mesh(const MeshData &mesh) {
    return voussoir::Mesh(mesh.positions, mesh.triangles, mesh.anchored);
}

Solution read_solution(const voussoir::Result &result) {
    Solution s;
    s.kind = result.kind();
    const voussoir::Counts counts = result.counts();
    s.n_vertices = counts.vertices, s.n_edges = counts.edges;
    s.n_faces = counts.faces, s.n_holes = counts.holes;
    s.positions = result.positions();
    s.edges = result.edges();
    s.force_densities = result.force_densities();
    s.weights = result.weights();
    s.airy = result.airy();
    s.loads = result.loads();
    s.external = result.external_horizontal();
    s.residuals = result.residuals();
    s.imbalance = result.horizontal_imbalance();
    s.holes = result.hole_coefficients();
    s.centres = result.force_diagram_centres();
    s.segments = result.force_diagram_segments();
    s.segment_edges = result.force_diagram_segment_edges();
    const voussoir::StressSummary stress = result.stress_summary();
    s.stress_status = stress.status;
    s.eps_inf = stress.eps_inf, s.objective = stress.objective;
    s.qp_iterations = stress.qp_iterations;
    if (s.kind == VSR_RESULT_KIND_FORM_FINDING) {
        const voussoir::Termination termination = result.termination();
        s.termination = termination.reason;
        s.iterations = termination.iterations;
        s.termination_message = result.termination_message();
    }
    return s;
}

const char *to_string(Solve solve) {
    return solve == Solve::Analysis ? "analysis" : "form finding";
}

Solution solve(const MeshData &mesh, Solve how, std::size_t max_iterations) {
    const voussoir::Mesh vmesh = make_mesh(mesh);
    voussoir::Settings settings;
    // reference_check explains the faces along hole cuts and the force diagram's closure
    // around holes by constant Airy jumps only (no net force through a hole).
    settings.max_iterations(max_iterations).hole_mode(VSR_HOLE_MODE_CONSTANT);
    return read_solution(how == Solve::Analysis ? voussoir::analyse(vmesh, settings)
                                                : voussoir::form_find(vmesh, settings));
}

// =============================================================================================
// Meshes built by CGAL: constrained Delaunay triangulation of the plan domain (outer polygon,
// hole polygons), Delaunay refinement with seeds marking the holes, heights from analytic
// functions.

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point2 = K::Point_2;
using Vector2 = K::Vector_2;
using Point3 = K::Point_3;
using Vector3 = K::Vector_3;
using WeightedPoint = K::Weighted_point_2;

using MeshVb = CGAL::Delaunay_mesh_vertex_base_2<K>;
using MeshFb = CGAL::Delaunay_mesh_face_base_2<K>;
using MeshTds = CGAL::Triangulation_data_structure_2<MeshVb, MeshFb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, MeshTds>;
using Criteria = CGAL::Delaunay_mesh_size_criteria_2<CDT>;

using Polygon = std::vector<Point2>;

constexpr double pi = 3.14159265358979323846;

Polygon circle(double cx, double cy, double r, int n) {
    Polygon p;
    for (int k = 0; k < n; ++k)
        p.emplace_back(cx + r * std::cos(2 * pi * k / n), cy + r * std::sin(2 * pi * k / n));
    return p;
}

struct Domain {
    std::string name;
    Polygon outer;
    std::vector<Polygon> holes;
    std::vector<Point2> seeds;   // one point inside each hole
    double size;                 // the mesher's bound on edge lengths
    std::function<double(double, double)> height;
    // Which boundary vertices are anchored (x, y of a boundary vertex).
    std::function<bool(double, double)> anchored;
};

MeshData triangulate(const Domain &d) {
    CDT cdt;
    cdt.insert_constraint(d.outer.begin(), d.outer.end(), true);
    for (const Polygon &hole : d.holes) cdt.insert_constraint(hole.begin(), hole.end(), true);
    // Shape bound 0.125 (minimum angle about 20.6 degrees), size bound d.size; the seeds'
    // connected components (the holes) are not meshed.
    CGAL::refine_Delaunay_mesh_2(cdt, d.seeds.begin(), d.seeds.end(), Criteria(0.125, d.size));

    MeshData m;
    m.name = d.name;
    std::map<CDT::Vertex_handle, uint32_t> id;
    std::set<uint32_t> boundary;
    auto vertex_id = [&](CDT::Vertex_handle v) {
        auto [it, inserted] = id.emplace(v, static_cast<uint32_t>(id.size()));
        if (inserted) {
            const Point2 &p = v->point();
            m.positions.insert(m.positions.end(), {p.x(), p.y(), d.height(p.x(), p.y())});
        }
        return it->second;
    };
    for (CDT::Face_handle f : cdt.finite_face_handles()) {
        if (!f->is_in_domain()) continue;
        for (int k = 0; k < 3; ++k) m.triangles.push_back(vertex_id(f->vertex(k)));
        for (int k = 0; k < 3; ++k) {
            CDT::Face_handle n = f->neighbor(k);
            if (cdt.is_infinite(n) || !n->is_in_domain()) {
                boundary.insert(vertex_id(f->vertex(CDT::cw(k))));
                boundary.insert(vertex_id(f->vertex(CDT::ccw(k))));
            }
        }
    }
    for (uint32_t v : boundary)
        if (d.anchored(m.positions[3 * v], m.positions[3 * v + 1])) m.anchored.push_back(v);
    return m;
}

// Spherical cap of plan radius `a` and rise `h` centred at the origin (0 on the rim).
double cap(double x, double y, double a, double h) {
    const double R = (a * a + h * h) / (2 * h);
    return std::sqrt(std::max(0.0, R * R - x * x - y * y)) - (R - h);
}

std::vector<Domain> domains() {
    std::vector<Domain> out;
    const auto on_unit_circle = [](double x, double y) { return std::hypot(x, y) > 0.99; };

    // A dome over a disk, rim anchored: the convex reference case.
    out.push_back({"disk_cap", circle(0, 0, 1, 72), {}, {}, 0.1,
                   [](double x, double y) { return cap(x, y, 1.0, 0.45); }, on_unit_circle});

    // A dome with an off-centre hole whose rim is free.
    out.push_back({"disk_off_centre_hole", circle(0, 0, 1, 72), {circle(0.35, 0.15, 0.25, 36)},
                   {Point2(0.35, 0.15)}, 0.1,
                   [](double x, double y) { return cap(x, y, 1.0, 0.5); }, on_unit_circle});

    // A vault over a square with a door opening cut into each side: the square's sides are
    // anchored, the jambs and lintels of the doors are free.
    Polygon square_doors;
    {
        const double w = 0.2, depth = 0.3;
        // One side, from corner (-1,-1) towards (1,-1), then rotated by 90 degrees three
        // times ((x, y) -> (-y, x) is exact).
        const std::vector<std::pair<double, double>> side = {
            {-1, -1}, {-w, -1}, {-w, -1 + depth}, {w, -1 + depth}, {w, -1}};
        for (int r = 0; r < 4; ++r)
            for (auto [x, y] : side) {
                for (int k = 0; k < r; ++k) std::tie(x, y) = std::make_pair(-y, x);
                square_doors.emplace_back(x, y);
            }
    }
    out.push_back({"square_with_doors", square_doors, {}, {}, 0.12,
                   [](double x, double y) { return 0.9 * (1 - x * x) * (1 - y * y); },
                   [](double x, double y) { return std::max(std::abs(x), std::abs(y)) > 0.999; }});

    // A dome with a central oculus (annulus, inner rim free).
    out.push_back({"annulus_oculus", circle(0, 0, 1, 72), {circle(0, 0, 0.3, 32)},
                   {Point2(0, 0)}, 0.1,
                   [](double x, double y) { return cap(x, y, 1.0, 0.5); }, on_unit_circle});

    // An annular barrel vault around an off-centre hole, both rims anchored: the hole
    // carries stress (non-zero hole coefficient).
    {
        const double cx = 0.15, cy = 0.05, r = 0.4;
        out.push_back({"annular_vault", circle(0, 0, 1, 72), {circle(cx, cy, r, 40)},
                       {Point2(cx, cy)}, 0.09,
                       [=](double x, double y) {
                           const double outer = std::max(0.0, 1 - std::hypot(x, y));
                           const double inner = std::max(0.0, std::hypot(x - cx, y - cy) - r);
                           const double s = inner / std::max(1e-12, inner + outer);
                           return 0.3 * std::sin(pi * s);
                       },
                       [](double, double) { return true; }});
    }
    return out;
}

}  // namespace

std::vector<std::string> generated_names() {
    std::vector<std::string> names;
    for (const Domain &d : domains()) names.push_back(d.name);
    return names;
}

MeshData generated(const std::string &name) {
    for (const Domain &d : domains())
        if (d.name == name) return triangulate(d);
    throw std::invalid_argument("no generated mesh named " + name);
}

// =============================================================================================
// Models read with OpenMesh (double-precision points).

namespace {

using OMesh = OpenMesh::TriMesh_ArrayKernelT<OpenMesh::DefaultTraitsDouble>;

std::string slurp(const std::string &path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read " + path);
    std::stringstream buffer;
    buffer << in.rdbuf();
    return buffer.str();
}

// The integers of the JSON array under `key` (enough for the models' sidecars).
std::vector<long> json_int_array(const std::string &text, const std::string &key) {
    const auto at = text.find("\"" + key + "\"");
    const auto open = at == std::string::npos ? at : text.find('[', at);
    const auto close = open == std::string::npos ? open : text.find(']', open);
    if (close == std::string::npos) throw std::runtime_error("no \"" + key + "\" array");
    std::vector<long> out;
    std::stringstream list(text.substr(open + 1, close - open - 1));
    std::string item;
    while (std::getline(list, item, ','))
        if (item.find_first_not_of(" \t\r\n") != std::string::npos) out.push_back(std::stol(item));
    return out;
}

// The integer under `key` inside the object under `object` ("counts": {"V": 360, ...}).
long json_int_in(const std::string &text, const std::string &object, const std::string &key) {
    const auto at = text.find("\"" + object + "\"");
    const auto k = at == std::string::npos ? at : text.find("\"" + key + "\"", at);
    const auto colon = k == std::string::npos ? k : text.find(':', k);
    if (colon == std::string::npos) throw std::runtime_error("no " + object + "." + key);
    return std::stol(text.substr(colon + 1));
}

MeshData from_openmesh(const OMesh &om, const std::string &name) {
    MeshData m;
    m.name = name;
    for (auto v : om.vertices())
        for (int c = 0; c < 3; ++c) m.positions.push_back(om.point(v)[c]);
    for (auto f : om.faces())
        for (auto v : om.fv_range(f)) m.triangles.push_back(static_cast<uint32_t>(v.idx()));
    return m;
}

}  // namespace

std::vector<std::string> model_names() {
    return {"free_vault", "dome_with_doors", "lilium", "cheese", "four_holes",
            "neumunster", "hex", "three_pillar", "vault_pq"};
}

std::string models_dir() { return VSR_MODELS_DIR; }

bool models_available() {
    return std::ifstream(models_dir() + "/neumunster.obj").good();
}

bool models_required() {
    const char *ci = std::getenv("CI");
    std::string value = ci ? ci : "";
    std::transform(value.begin(), value.end(), value.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool in_ci = !value.empty() && value != "0" && value != "false";
    const char *require = std::getenv("VSR_REQUIRE_MODELS");
    return in_ci || (require && std::string(require) == "1");
}

MeshData read_mesh_file(const std::string &path) {
    OMesh om;
    if (!OpenMesh::IO::read_mesh(om, path)) throw std::runtime_error("OpenMesh cannot read " + path);
    return from_openmesh(om, path);
}

MeshData read_model(const std::string &name) {
    const std::string base = models_dir() + "/" + name;
    MeshData m = read_mesh_file(base + ".obj");
    m.name = name;
    const std::string json = slurp(base + ".json");
    for (long id : json_int_array(json, "anchored")) {
        if (id < 0) throw std::runtime_error(name + ".json: negative id");
        m.anchored.push_back(static_cast<uint32_t>(id));
    }
    // OpenMesh must have read the model as it is (no vertex duplicated for a complex edge).
    const long V = json_int_in(json, "counts", "V"), F = json_int_in(json, "counts", "F");
    if (static_cast<long>(m.n_vertices()) != V || static_cast<long>(m.n_faces()) != F)
        throw std::runtime_error(name + ": OpenMesh read " + std::to_string(m.n_vertices()) +
                                 " vertices and " + std::to_string(m.n_faces()) +
                                 " faces; the sidecar says " + std::to_string(V) + " and " +
                                 std::to_string(F));
    return m;
}

std::string write_mesh_file(const MeshData &mesh, const std::vector<double> &positions,
                            const std::string &file_name) {
    if (positions.size() != mesh.positions.size())
        throw std::invalid_argument("write_mesh_file: positions do not match the mesh");
    OMesh om;
    std::vector<OMesh::VertexHandle> vh;
    for (std::size_t i = 0; i < mesh.n_vertices(); ++i)
        vh.push_back(om.add_vertex(
            OMesh::Point(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2])));
    for (std::size_t t = 0; t < mesh.n_faces(); ++t) {
        auto f = om.add_face(vh[mesh.triangles[3 * t]], vh[mesh.triangles[3 * t + 1]],
                             vh[mesh.triangles[3 * t + 2]]);
        if (!f.is_valid()) throw std::runtime_error("OpenMesh rejected face " + std::to_string(t));
    }
    const std::string path = std::string(VSR_OUTPUT_DIR) + "/" + file_name;
    if (!OpenMesh::IO::write_mesh(om, path, OpenMesh::IO::Options::Default, 17))
        throw std::runtime_error("OpenMesh cannot write " + path);
    return path;
}

// =============================================================================================
// The reference checker.

namespace {

using RtVb = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, K,
                                                         CGAL::Regular_triangulation_vertex_base_2<K>>;
using RtFb = CGAL::Regular_triangulation_face_base_2<K>;
using RtTds = CGAL::Triangulation_data_structure_2<RtVb, RtFb>;
using Regular = CGAL::Regular_triangulation_2<K, RtTds>;

std::string fmt(const char *format, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char *format, ...) {
    char buffer[512];
    va_list args;
    va_start(args, format);
    std::vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    return buffer;
}

// An undirected edge of the mesh with its two sides: `left` is the face in which the edge
// runs a -> b counter-clockwise in plan (its third vertex is left of a -> b), `right` the
// other (-1 on the boundary).
struct Edge {
    uint32_t a, b;
    long left = -1, right = -1;
    bool interior() const { return left >= 0 && right >= 0; }
};

}  // namespace

std::string CheckReport::summary() const {
    std::string s = fmt(
        "eps_inf %.3e (library %.3e), max horizontal %.2e (free boundary %.2e), max |dual/l - q| %.2e of max q over "
        "%zu of %zu interior edges (%zu skipped: %zu faces on hole cuts, %zu explained by one "
        "hole's jump), closure %.1e, loads %.2e, "
        "residual vs library %.2e, min q / max q %.3e; regular triangulation: %s (%zu edges, "
        "%zu hidden)",
        eps_inf, eps_inf_reported, max_horizontal, max_horizontal_free, max_dual, dual_checked, interior_edges,
        dual_skipped_cut, cut_faces, cut_faces_explained, max_closure, max_load, max_residual_vs_library, min_q_ratio, regular_note.c_str(),
        regular_checked, hidden_vertices);
    for (const std::string &f : failures) s += "\n  FAIL " + f;
    return s;
}

CheckReport reference_check(const MeshData &mesh, const Solution &sol,
                            const CheckOptions &options) {
    CheckReport rep;
    // Each failure starts with its check's name in brackets: [mesh], [plan], [loads],
    // [horizontal], [vertical], [compression], [centres], [dual], [holes], [regular].
    auto fail = [&](const char *check, const std::string &what) {
        rep.failed_checks.insert(check);
        if (rep.failures.size() < 40) rep.failures.push_back("[" + std::string(check) + "] " + what);
    };
    const std::size_t nv = mesh.n_vertices(), nf = mesh.n_faces();
    if (sol.n_vertices != nv || sol.n_faces != nf || sol.positions.size() != 3 * nv ||
        sol.weights.size() != nv || sol.loads.size() != nv || sol.external.size() != 2 * nv) {
        fail("mesh", "array sizes do not match the mesh");
        return rep;
    }
    const auto &x = sol.positions;
    auto plan = [&](uint32_t v) { return Point2(x[3 * v], x[3 * v + 1]); };
    auto space = [&](uint32_t v) { return Point3(x[3 * v], x[3 * v + 1], x[3 * v + 2]); };

    // --- Connectivity from the input triangles (not from the library).
    std::map<std::pair<uint32_t, uint32_t>, Edge> edge_map;
    std::vector<char> referenced(nv, 0), anchored(nv, 0);
    for (uint32_t v : mesh.anchored) anchored.at(v) = 1;
    for (std::size_t t = 0; t < nf; ++t) {
        std::array<uint32_t, 3> f = {mesh.triangles[3 * t], mesh.triangles[3 * t + 1],
                                     mesh.triangles[3 * t + 2]};
        if (CGAL::orientation(plan(f[0]), plan(f[1]), plan(f[2])) == CGAL::CLOCKWISE)
            std::swap(f[1], f[2]);
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = f[k], b = f[(k + 1) % 3];
            referenced[a] = 1;
            Edge &e = edge_map[{std::min(a, b), std::max(a, b)}];
            e.a = std::min(a, b);
            e.b = std::max(a, b);
            (a < b ? e.left : e.right) = static_cast<long>(t);
        }
    }
    std::vector<Edge> edges;
    for (const auto &kv : edge_map) edges.push_back(kv.second);   // sorted (a, b)
    // The library's edge order must be this one (row e of every per-edge array).
    if (sol.edges.size() != 2 * edges.size() || sol.force_densities.size() != edges.size()) {
        fail("mesh", fmt("library has %zu edges, the mesh %zu", sol.edges.size() / 2, edges.size()));
        return rep;
    }
    for (std::size_t e = 0; e < edges.size(); ++e)
        if (sol.edges[2 * e] != edges[e].a || sol.edges[2 * e + 1] != edges[e].b) {
            fail("mesh", fmt("edge %zu is (%u, %u) in the library, (%u, %u) here", e, sol.edges[2 * e],
                     sol.edges[2 * e + 1], edges[e].a, edges[e].b));
            return rep;
        }
    const std::vector<double> &q = sol.force_densities;

    // --- Plan and supports unchanged (no ODT in these tests).
    for (std::size_t v = 0; v < nv; ++v) {
        if (x[3 * v] != mesh.positions[3 * v] || x[3 * v + 1] != mesh.positions[3 * v + 1])
            fail("plan", fmt("vertex %zu moved in plan", v));
        if (anchored[v] && x[3 * v + 2] != mesh.positions[3 * v + 2])
            fail("plan", fmt("anchored vertex %zu moved", v));
    }

    // --- Loads: density × one third of each incident 3-D triangle area.
    std::vector<double> load(nv, 0.0);
    for (std::size_t t = 0; t < nf; ++t) {
        const uint32_t a = mesh.triangles[3 * t], b = mesh.triangles[3 * t + 1],
                       c = mesh.triangles[3 * t + 2];
        const Vector3 n = CGAL::cross_product(space(b) - space(a), space(c) - space(a));
        const double share = options.density * 0.5 * std::sqrt(n.squared_length()) / 3.0;
        load[a] += share;
        load[b] += share;
        load[c] += share;
    }
    const double max_load = *std::max_element(load.begin(), load.end());
    for (std::size_t v = 0; v < nv; ++v) {
        const double d = std::abs(load[v] - sol.loads[v]) / max_load;
        rep.max_load = std::max(rep.max_load, d);
        if (!(d <= options.load_tolerance))
            fail("loads", fmt("load of vertex %zu: %.17g here, %.17g returned", v, load[v], sol.loads[v]));
    }

    // --- Equilibrium: Σ_j q_ij (x_i − x_j) with CGAL vectors; horizontal + P_i, vertical − p_i.
    std::vector<Vector3> force(nv, CGAL::NULL_VECTOR);
    std::vector<double> scale(nv, 0.0);
    double q_max = 0, q_min_interior = INFINITY;
    for (std::size_t e = 0; e < edges.size(); ++e) {
        const Vector3 d = space(edges[e].a) - space(edges[e].b);
        force[edges[e].a] = force[edges[e].a] + q[e] * d;
        force[edges[e].b] = force[edges[e].b] - q[e] * d;
        const double l = std::sqrt(CGAL::squared_distance(plan(edges[e].a), plan(edges[e].b)));
        scale[edges[e].a] += std::abs(q[e]) * l;
        scale[edges[e].b] += std::abs(q[e]) * l;
        if (!std::isfinite(q[e])) fail("compression", fmt("q of edge %zu is not finite", e));
        if (edges[e].interior()) {
            ++rep.interior_edges;
            q_max = std::max(q_max, std::abs(q[e]));
            q_min_interior = std::min(q_min_interior, q[e]);
        }
    }
    for (std::size_t e = 0; e < edges.size(); ++e)
        if (!edges[e].interior()) q_max = std::max(q_max, std::abs(q[e]));
    std::vector<char> on_boundary(nv, 0);
    for (const Edge &e : edges)
        if (!e.interior()) on_boundary[e.a] = on_boundary[e.b] = 1;
    double sum_p = 0;
    for (std::size_t v = 0; v < nv; ++v)
        if (referenced[v] && !anchored[v]) {
            ++rep.non_anchored;
            sum_p += load[v];
        }
    const double mean_p = rep.non_anchored ? sum_p / static_cast<double>(rep.non_anchored) : 0;
    double max_r = 0, max_r_diff = 0;
    for (std::size_t v = 0; v < nv; ++v) {
        if (!referenced[v] || anchored[v]) continue;
        // Horizontal: relative to the vertex's own force magnitudes plus the mean load.
        const Vector2 h(force[v].x() + sol.external[2 * v], force[v].y() + sol.external[2 * v + 1]);
        const double hn = std::sqrt(h.squared_length());
        const double hs =
            scale[v] + std::hypot(sol.external[2 * v], sol.external[2 * v + 1]) + mean_p;
        double &worst = on_boundary[v] ? rep.max_horizontal_free : rep.max_horizontal;
        worst = std::max(worst, hn / hs);
        const double tol =
            on_boundary[v] ? options.free_horizontal_tolerance : options.horizontal_tolerance;
        if (!(hn <= tol * hs))
            fail("horizontal", fmt("%s vertex %zu: horizontal imbalance %.3e (scale %.3e)",
                     on_boundary[v] ? "free boundary" : "interior", v, hn, hs));
        const double r = force[v].z() - load[v];
        max_r = std::max(max_r, std::abs(r));
        max_r_diff = std::max(max_r_diff, std::abs(r - sol.residuals[v]));
    }
    if (rep.non_anchored == 0) {
        fail("mesh", "no non-anchored vertex");
        return rep;
    }
    rep.eps_inf = max_r / mean_p;
    rep.eps_inf_reported = sol.eps_inf;
    rep.max_residual_vs_library = max_r_diff / mean_p;
    if (!(std::abs(rep.eps_inf - sol.eps_inf) <= 1e-6 * sol.eps_inf + 1e-12))
        fail("vertical", fmt("eps_inf recomputed %.9e, reported %.9e", rep.eps_inf, sol.eps_inf));
    if (!(rep.max_residual_vs_library <= 1e-9))
        fail("vertical", fmt("returned residuals differ from the recomputed ones by %.3e of the mean load",
                 rep.max_residual_vs_library));
    if (options.vertical_tolerance >= 0 && !(rep.eps_inf < options.vertical_tolerance))
        fail("vertical", fmt("not in vertical equilibrium: eps_inf %.3e >= %.3e", rep.eps_inf,
                 options.vertical_tolerance));
    rep.min_q_ratio = q_min_interior / q_max;
    if (!(q_min_interior >= -1e-9 * q_max))
        fail("compression", fmt("tension: min interior q %.3e (max %.3e)", q_min_interior, q_max));

    // --- Holes: is the Airy function single-valued (all hole coefficients ~0)?
    double bbox_diag = 0;
    {
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (std::size_t v = 0; v < nv; ++v)
            if (referenced[v])
                for (int c = 0; c < 2; ++c) {
                    lo[c] = std::min(lo[c], x[3 * v + c]);
                    hi[c] = std::max(hi[c], x[3 * v + c]);
                }
        bbox_diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1]);
    }
    // A hole counts as stress-free when its jump cannot move a power centre beyond the
    // tolerance of (a) below: shifting one weight by 2c moves a face's centre by at most
    // 2c / (2 h) for its smallest altitude h. (A threshold on c alone, relative to q_max and
    // the diagonal, let a c of 5e-8 on free_vault move centres 450× the tolerance.)
    double min_altitude = INFINITY;
    for (std::size_t t = 0; t < nf; ++t) {
        const Point2 p[3] = {plan(mesh.triangles[3 * t]), plan(mesh.triangles[3 * t + 1]),
                             plan(mesh.triangles[3 * t + 2])};
        const double area2 = std::abs(CGAL::area(p[0], p[1], p[2])) * 2;
        double longest = 0;
        for (int k = 0; k < 3; ++k)
            longest = std::max(longest, std::sqrt(CGAL::squared_distance(p[k], p[(k + 1) % 3])));
        if (longest > 0) min_altitude = std::min(min_altitude, area2 / longest);
    }
    const double jump_tolerance = 0.1 * options.dual_tolerance * q_max * bbox_diag * min_altitude;
    for (std::size_t h = 0; h < sol.holes.size() / 3; ++h) {
        const double c = std::abs(sol.holes[3 * h]);
        const double a = std::hypot(sol.holes[3 * h + 1], sol.holes[3 * h + 2]);
        if (c > jump_tolerance || a * bbox_diag > jump_tolerance) rep.holes_zero = false;
    }

    // --- (a) Power centres of the weighted plan points (CGAL) give q = d*/l on interior edges.
    //
    // With non-zero hole coefficients the Airy function is multivalued: it jumps by c_h around
    // hole h. The library cuts the domain along a tree of paths (each from a hole to the outer
    // loop or to another hole), across which it jumps by the sum of the c_h of the holes cut
    // through that path, and the returned single-valued weights
    // cannot hold it on the faces along the cut (their power centres are off). (a) is then
    // checked directly only on the edges whose two faces are away from the cuts:
    //  - the cut faces are located with the library's force diagram centres (the gradient of
    //    the face-local Airy function): a face is on a cut when its centre differs from the
    //    CGAL power centre. Off the cuts the two must agree, and in every mesh without hole
    //    stress they must agree on every face;
    //  - on a cut face, the library's centre must be the CGAL power centre of the weights with
    //    a non-empty proper subset of the face's vertices shifted by ∓2 c_h for one hole h
    //    (φ ± c_h). With one hole this is required of every cut face (it checks the returned
    //    c_h); with several, a cut carries the sum of several holes' jumps and cuts share
    //    vertices, so the faces explained by one hole's jump are only counted;
    //  - on edges with a cut face, d*/l from the library's centres must equal q;
    //  - the cut faces are at most a quarter of the faces;
    //  - independently of the weights, the force diagram integrated from q alone across
    //    interior edges (g_right = g_left − q_e l_e n_e) must close around every interior
    //    vertex and hole (horizontal equilibrium; a constant jump carries no net force).
    std::vector<Point2> centre(nf);
    for (std::size_t t = 0; t < nf; ++t) {
        const uint32_t a = mesh.triangles[3 * t], b = mesh.triangles[3 * t + 1],
                       c = mesh.triangles[3 * t + 2];
        centre[t] = CGAL::weighted_circumcenter(WeightedPoint(plan(a), sol.weights[a]),
                                                WeightedPoint(plan(b), sol.weights[b]),
                                                WeightedPoint(plan(c), sol.weights[c]));
    }
    // A centre moved by δ changes d*/l of the face's edges by at most δ / (smallest altitude):
    // below this, a face's offset (a small hole jump, say) keeps its edges within tolerance.
    const double tol_point = 0.5 * options.dual_tolerance * q_max * min_altitude;
    std::vector<char> on_cut(nf, 0);
    if (sol.centres.size() != 2 * nf) {
        fail("mesh", fmt("library has %zu force diagram centres for %zu faces",
                         sol.centres.size() / 2, nf));
        return rep;
    }
    std::size_t unexplained = 0;
    const std::size_t n_holes = sol.holes.size() / 3;
    for (std::size_t t = 0; t < nf; ++t) {
        const Point2 lib(sol.centres[2 * t], sol.centres[2 * t + 1]);
        const double off = std::sqrt(CGAL::squared_distance(centre[t], lib));
        if (off <= tol_point) continue;
        if (rep.holes_zero) {
            fail("centres", fmt("face %zu: library centre off the power centre by %.3e", t, off));
            continue;
        }
        on_cut[t] = 1;
        ++rep.cut_faces;
        bool explained = false;
        const uint32_t f[3] = {mesh.triangles[3 * t], mesh.triangles[3 * t + 1],
                               mesh.triangles[3 * t + 2]};
        for (std::size_t h = 0; h < n_holes && !explained; ++h)
            for (double sign : {1.0, -1.0})
                for (int subset = 1; subset < 7 && !explained; ++subset) {
                    WeightedPoint wp[3];
                    for (int k = 0; k < 3; ++k) {
                        const double shift = (subset >> k) & 1 ? 2 * sign * sol.holes[3 * h] : 0.0;
                        wp[k] = WeightedPoint(plan(f[k]), sol.weights[f[k]] - shift);
                    }
                    const Point2 c = CGAL::weighted_circumcenter(wp[0], wp[1], wp[2]);
                    explained = std::sqrt(CGAL::squared_distance(c, lib)) <= tol_point;
                }
        if (explained) {
            ++rep.cut_faces_explained;
        } else if (n_holes == 1 && ++unexplained <= 10) {
            fail("holes", fmt("face %zu: power centre off the library's by %.3e, not explained "
                              "by the hole's jump",
                              t, off));
        }
    }
    if (4 * rep.cut_faces > nf)
        fail("holes", fmt("%zu of %zu faces are on hole cuts: more than cuts", rep.cut_faces, nf));

    for (std::size_t e = 0; e < edges.size(); ++e) {
        if (!edges[e].interior()) continue;
        const Vector2 d = plan(edges[e].b) - plan(edges[e].a);
        const double l = std::sqrt(d.squared_length());
        const Vector2 n = d.perpendicular(CGAL::COUNTERCLOCKWISE) / l;   // towards the left face
        const std::size_t L = edges[e].left, R = edges[e].right;
        if (on_cut[L] || on_cut[R]) {
            ++rep.dual_skipped_cut;
            const Point2 cl(sol.centres[2 * L], sol.centres[2 * L + 1]);
            const Point2 cr(sol.centres[2 * R], sol.centres[2 * R + 1]);
            const double err = std::abs(((cl - cr) * n) / l - q[e]) / q_max;
            if (!(err <= options.dual_tolerance))
                fail("dual", fmt("edge %zu (%u, %u) on a hole cut: d*/l from the library's "
                                 "centres differs from q by %.2e of max q",
                                 e, edges[e].a, edges[e].b, err));
            continue;
        }
        const double dual = (centre[L] - centre[R]) * n;
        const double err = std::abs(dual / l - q[e]) / q_max;
        ++rep.dual_checked;
        rep.max_dual = std::max(rep.max_dual, err);
        if (!(err <= options.dual_tolerance))
            fail("dual", fmt("edge %zu (%u, %u): d*/l = %.12e from the power centres, q = %.12e "
                             "(%.2e of max q)",
                             e, edges[e].a, edges[e].b, dual / l, q[e], err));
    }

    {   // The force diagram from q alone closes.
        std::vector<Vector2> g(nf, CGAL::NULL_VECTOR);
        std::vector<char> seen(nf, 0);
        std::vector<std::vector<std::size_t>> face_edges(nf);
        for (std::size_t e = 0; e < edges.size(); ++e)
            if (edges[e].interior()) {
                face_edges[edges[e].left].push_back(e);
                face_edges[edges[e].right].push_back(e);
            }
        double closure = 0;
        for (std::size_t root = 0; root < nf; ++root) {
            if (seen[root]) continue;
            seen[root] = 1;
            std::vector<std::size_t> stack = {root};
            while (!stack.empty()) {
                const std::size_t t = stack.back();
                stack.pop_back();
                for (std::size_t e : face_edges[t]) {
                    const Vector2 d = plan(edges[e].b) - plan(edges[e].a);
                    const Vector2 jump = q[e] * d.perpendicular(CGAL::COUNTERCLOCKWISE);
                    const bool from_left = static_cast<long>(t) == edges[e].left;
                    const std::size_t o = from_left ? edges[e].right : edges[e].left;
                    const Vector2 go = from_left ? g[t] - jump : g[t] + jump;
                    if (!seen[o]) {
                        seen[o] = 1;
                        g[o] = go;
                        stack.push_back(o);
                    } else {
                        closure = std::max(closure, std::sqrt((g[o] - go).squared_length()));
                    }
                }
            }
        }
        rep.max_closure = closure / (q_max * bbox_diag);
        if (!(closure <= options.dual_tolerance * q_max * bbox_diag))
            fail("dual", fmt("the force diagram integrated from q does not close: %.3e of "
                             "max q × plan diagonal",
                             rep.max_closure));
    }

    // --- (b) Where all interior q > 0, every interior edge is an edge of the regular
    // triangulation of the weighted plan points, and no vertex is hidden. With non-zero hole
    // coefficients the Airy function is multivalued and has no single lifted surface: the
    // returned weights hide vertices near the cuts, and leaving out the cut faces' vertices
    // does not help (the branches on the two sides of a cut differ by c_h, so the convex
    // hull bridges the gap and still hides vertices). (b) is then not applied.
    rep.all_positive = q_min_interior > 1e-9 * q_max;
    if (!rep.all_positive) {
        rep.regular_note = "not applied (some interior q <= 1e-9 max q)";
    } else if (!rep.holes_zero) {
        rep.regular_note = "not applied (non-zero hole coefficients: multivalued Airy function)";
    } else {
        rep.regular_applies = true;
        const std::vector<char> &keep = referenced;
        std::vector<std::pair<WeightedPoint, uint32_t>> sites;
        for (uint32_t v = 0; v < nv; ++v)
            if (keep[v]) sites.emplace_back(WeightedPoint(plan(v), sol.weights[v]), v);
        Regular rt;
        rt.insert(sites.begin(), sites.end());
        rep.hidden_vertices = rt.number_of_hidden_vertices();
        if (rep.hidden_vertices != 0 || rt.number_of_vertices() != sites.size())
            fail("regular", fmt("regular triangulation hides %zu of %zu vertices",
                                rep.hidden_vertices, sites.size()));
        std::vector<Regular::Vertex_handle> handle(nv);
        for (Regular::Vertex_handle vh : rt.finite_vertex_handles()) handle[vh->info()] = vh;
        std::size_t missing = 0;
        for (std::size_t e = 0; e < edges.size(); ++e) {
            if (!edges[e].interior() || !keep[edges[e].a] || !keep[edges[e].b]) continue;
            const Regular::Vertex_handle va = handle[edges[e].a], vb = handle[edges[e].b];
            ++rep.regular_checked;
            if (va == Regular::Vertex_handle() || vb == Regular::Vertex_handle() ||
                !rt.is_edge(va, vb)) {
                if (++missing <= 10)
                    fail("regular", fmt("interior edge %zu (%u, %u) with q = %.3e is not an "
                                        "edge of the regular triangulation",
                                        e, edges[e].a, edges[e].b, q[e]));
            }
        }
        if (missing > 10) fail("regular", fmt("... %zu interior edges missing in all", missing));
        rep.regular_note = "applied";
    }
    return rep;
}

std::vector<std::array<uint32_t, 2>> sorted_edges(const MeshData &mesh) {
    std::set<std::array<uint32_t, 2>> edges;
    for (std::size_t t = 0; t < mesh.n_faces(); ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = mesh.triangles[3 * t + k], b = mesh.triangles[3 * t + (k + 1) % 3];
            edges.insert({std::min(a, b), std::max(a, b)});
        }
    return {edges.begin(), edges.end()};
}

}  // namespace vsrt
