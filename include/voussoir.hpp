/*
 * voussoir.hpp: C++17 API of Voussoir, header-only over the C API (voussoir.h).
 *
 *   voussoir::Mesh mesh(positions, triangles, supports);      // std::vector<double>, <uint32_t>
 *   voussoir::Settings settings;
 *   settings.max_iterations(100).fairness(0.05);
 *   voussoir::Result result = voussoir::form_find(mesh, settings);
 *   std::vector<double> shape = result.positions();
 *
 *   // Masonry assessment: a thrust surface inside a 0.1 thick masonry about the mesh.
 *   voussoir::AssessSettings assess_settings;
 *   assess_settings.objective(VSR_OBJECTIVE_MIN_THICKNESS);
 *   voussoir::Assessment a = voussoir::assess(mesh, voussoir::Envelope::from_thickness(mesh, 0.1),
 *                                             assess_settings);
 *   double safety = a.figures().safety_factor;
 *
 * Link with Voussoir::voussoir (CMake: find_package(Voussoir CONFIG REQUIRED)) or with
 * `pkg-config --libs voussoir`; nothing else is needed. The adapters voussoir/cgal.hpp and
 * voussoir/openmesh.hpp convert CGAL and OpenMesh meshes.
 *
 * Ownership. Mesh, Settings, Result, Envelope, AssessSettings and Assessment own one C
 * handle each: move-only, freed by the destructor. A moved-from object is empty (get() is
 * NULL); every call on it fails with VSR_STATUS_NULL_POINTER. get() lends the handle to the C API; release() gives it up.
 *
 * Errors. Calls throw voussoir::Error, which carries the C status and a copy of the library's
 * one-line message (vsr_last_error_message) taken on the throwing thread. Each fallible call
 * has a non-throwing twin named try_...: noexcept, it returns the VsrStatus and leaves the
 * message in voussoir::last_error_message() (per thread, until the next call), exactly as the
 * C API does. A form finding that does not converge is not an error: read
 * Result::termination().
 *
 * Arrays. As in the C API: positions #V by 3 doubles (x, y plan, z height), triangles #F by 3
 * vertex ids, row-major; per-edge arrays follow Mesh::edges() / Result::edges(). Getters
 * return a std::vector, or fill a caller's vector (reusing its capacity), or copy into a
 * caller's buffer (throwing VSR_STATUS_BUFFER_TOO_SMALL when it is short).
 *
 * Thread safety (the C header's rules). Any call may be made from any thread. A const object
 * (Mesh and Settings passed to a solve, every Result getter) may be used by several threads at
 * once; a non-const call (setters, assignment, destruction) needs exclusive access. Solves on
 * shared const objects run concurrently and give the same results as run one after another.
 * The last error message is per thread. The progress callback runs on the thread that called
 * form_find; when settings are shared by concurrent solves it is called concurrently, so it
 * must then be safe to call from several threads.
 */
#ifndef VOUSSOIR_HPP
#define VOUSSOIR_HPP

#include <voussoir.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace voussoir {

/// The library's version ("MAJOR.MINOR.PATCH") and C ABI version, read at run time.
inline const char *version() noexcept { return vsr_version(); }
inline std::uint32_t abi_version() noexcept { return vsr_abi_version(); }
/// True when the library loaded at run time has the ABI this header was written for.
inline bool abi_compatible() noexcept { return vsr_abi_version() == VSR_ABI_VERSION; }

/// The one-line message of the last failed call on this thread ("" after a success). It
/// stays valid until the next call on this thread; copy it to keep it.
inline const char *last_error_message() noexcept { return vsr_last_error_message(); }
/// "VSR_STATUS_OK", "VSR_STATUS_INVALID_ARGUMENT", ...
inline const char *status_name(VsrStatus status) noexcept { return vsr_status_name(status); }

/// A failed call: the C status and the library's message. what() is "NAME: message".
class Error : public std::runtime_error {
  public:
    Error(VsrStatus status, const std::string &message)
        : std::runtime_error(std::string(vsr_status_name(status)) + ": " + message),
          status_(status),
          message_(message) {}
    VsrStatus status() const noexcept { return status_; }
    /// The library's message exactly as vsr_last_error_message() gave it.
    const std::string &message() const noexcept { return message_; }

  private:
    VsrStatus status_;
    std::string message_;
};

/// Throws Error (with this thread's last error message) unless `status` is VSR_STATUS_OK.
inline void check(VsrStatus status) {
    if (status != VSR_STATUS_OK) throw Error(status, vsr_last_error_message());
}

/// What the progress callback tells form finding.
enum class Progress { Continue, Cancel };
/// Called once per form-finding iteration with the 0-based iteration and the ε∞ the loop
/// goes on with (see VsrProgressFn). An exception it throws cancels the solve and is
/// rethrown by form_find.
using ProgressFn = std::function<Progress(std::size_t iteration, double eps_inf)>;

namespace detail {

template <typename Handle, void (*Destroy)(Handle *)>
class Owner {
  public:
    Owner() noexcept = default;
    explicit Owner(Handle *handle) noexcept : handle_(handle) {}
    Owner(const Owner &) = delete;
    Owner &operator=(const Owner &) = delete;
    Owner(Owner &&other) noexcept : handle_(other.release()) {}
    Owner &operator=(Owner &&other) noexcept {
        if (this != &other) reset(other.release());
        return *this;
    }
    ~Owner() { Destroy(handle_); }

    Handle *get() const noexcept { return handle_; }
    Handle *release() noexcept { return std::exchange(handle_, nullptr); }
    void reset(Handle *handle = nullptr) noexcept { Destroy(std::exchange(handle_, handle)); }
    explicit operator bool() const noexcept { return handle_ != nullptr; }

  private:
    Handle *handle_ = nullptr;
};

template <typename T, typename Handle>
using CopyOut = VsrStatus (*)(const Handle *, T *, std::size_t, std::size_t *);

// Size query, then copy: the C API's copy-out protocol.
template <typename T, typename Handle>
void copy_into(CopyOut<T, Handle> getter, const Handle *handle, std::vector<T> &out) {
    std::size_t needed = 0;
    check(getter(handle, nullptr, 0, &needed));
    out.resize(needed);
    if (needed != 0) check(getter(handle, out.data(), out.size(), &needed));
}

template <typename T, typename Handle>
std::size_t copy_into(CopyOut<T, Handle> getter, const Handle *handle, T *out, std::size_t len) {
    std::size_t needed = 0;
    check(getter(handle, out, len, &needed));
    return needed;
}

// Exceptions from a progress callback, kept on the solving thread until form_find returns.
inline std::exception_ptr &progress_exception() {
    static thread_local std::exception_ptr pending;
    return pending;
}

inline int progress_trampoline(void *user, std::size_t iteration, double eps_inf) {
    try {
        const ProgressFn &fn = *static_cast<const ProgressFn *>(user);
        return fn(iteration, eps_inf) == Progress::Cancel ? 1 : 0;
    } catch (...) {
        // Nothing may unwind through the C library: keep the exception and cancel.
        progress_exception() = std::current_exception();
        return 1;
    }
}

// Numbers of rows of a flat row-major array, or an Error naming it.
inline std::size_t rows(std::size_t size, std::size_t width, const char *argument) {
    if (size % width != 0)
        throw Error(VSR_STATUS_INVALID_ARGUMENT, "`" + std::string(argument) + "` has " +
                                                     std::to_string(size) + " values, not " +
                                                     std::to_string(width) + " per row");
    return size / width;
}

}  // namespace detail

// Three forms of each copy-out getter: a new vector, a caller's vector (capacity reused), a
// caller's buffer (returns the element count), and the try_ twin with the C signature.
#define VOUSSOIR_DETAIL_GETTER(Type, name, c_function, Handle)                          \
    std::vector<Type> name() const {                                                    \
        std::vector<Type> out;                                                          \
        name(out);                                                                      \
        return out;                                                                     \
    }                                                                                   \
    void name(std::vector<Type> &out) const {                                           \
        detail::copy_into<Type, Handle>(c_function, get(), out);                        \
    }                                                                                   \
    std::size_t name(Type *out, std::size_t len) const {                                \
        return detail::copy_into<Type, Handle>(c_function, get(), out, len);            \
    }                                                                                   \
    [[nodiscard]] VsrStatus try_##name(Type *out, std::size_t len, std::size_t *needed) \
        const noexcept {                                                                \
        return c_function(get(), out, len, needed);                                     \
    }

/// Sizes of a mesh or result (vsr_mesh_counts).
struct Counts {
    std::size_t vertices = 0, edges = 0, faces = 0, holes = 0;
};

/// Options of Mesh::read (those of vsr_mesh_read).
struct ReadOptions {
    std::string supports_path;            ///< JSON file of anchored ids; empty: `anchored`
    std::vector<std::uint32_t> anchored;  ///< the file's vertex ids of the supports
    double weld_tolerance = 1e-9;         ///< × bounding-box diagonal
    double repair_tolerance = 1e-4;       ///< × median plan area; 0 mends nothing, rejects those 1e-4 mends
};

/// A validated triangle mesh, its supports and loads (VsrMesh).
class Mesh {
  public:
    Mesh() noexcept = default;
    /// Adopts a handle from vsr_mesh_create / vsr_mesh_read (NULL: an empty Mesh).
    explicit Mesh(VsrMesh *handle) noexcept : owner_(handle) {}
    /// Positions #V by 3, triangles #F by 3, supports: vertex ids. Throws Error.
    Mesh(const std::vector<double> &positions, const std::vector<std::uint32_t> &triangles,
         const std::vector<std::uint32_t> &anchored) {
        check(try_create(positions.data(), detail::rows(positions.size(), 3, "positions"),
                         triangles.data(), detail::rows(triangles.size(), 3, "triangles"),
                         anchored.data(), anchored.size(), *this));
    }
    [[nodiscard]] static VsrStatus try_create(const double *positions, std::size_t n_vertices,
                                              const std::uint32_t *triangles,
                                              std::size_t n_triangles,
                                              const std::uint32_t *anchored, std::size_t n_anchored,
                                              Mesh &out) noexcept {
        VsrMesh *raw = nullptr;
        const VsrStatus status = vsr_mesh_create(positions, n_vertices, triangles, n_triangles,
                                                 anchored, n_anchored, &raw);
        if (status == VSR_STATUS_OK) out.owner_.reset(raw);
        return status;
    }

    /// Reads OBJ, OFF, STL or PLY (vsr_mesh_read); `merged` receives the welded count.
    static Mesh read(const std::string &path, const ReadOptions &options = ReadOptions(),
                     std::size_t *merged = nullptr) {
        Mesh mesh;
        check(try_read(path, options, mesh, merged));
        return mesh;
    }
    [[nodiscard]] static VsrStatus try_read(const std::string &path, const ReadOptions &options,
                                            Mesh &out, std::size_t *merged = nullptr) noexcept {
        VsrMesh *raw = nullptr;
        const VsrStatus status = vsr_mesh_read(
            path.c_str(), options.supports_path.empty() ? nullptr : options.supports_path.c_str(),
            options.anchored.data(), options.anchored.size(), options.weld_tolerance,
            options.repair_tolerance, merged, &raw);
        if (status == VSR_STATUS_OK) out.owner_.reset(raw);
        return status;
    }

    VsrMesh *get() const noexcept { return owner_.get(); }
    VsrMesh *release() noexcept { return owner_.release(); }
    explicit operator bool() const noexcept { return static_cast<bool>(owner_); }

    Counts counts() const {
        Counts c;
        check(vsr_mesh_counts(get(), &c.vertices, &c.edges, &c.faces, &c.holes));
        return c;
    }
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, edges, vsr_mesh_edges, VsrMesh)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, welded_ids, vsr_mesh_welded_ids, VsrMesh)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, plan_flips, vsr_mesh_plan_flips, VsrMesh)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, plan_nudges, vsr_mesh_plan_nudges, VsrMesh)
    /// The marked polygon diagonals: #D by 2 vertex ids (vsr_mesh_polygon_diagonals).
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, polygon_diagonals, vsr_mesh_polygon_diagonals,
                           VsrMesh)

    /// Marks the edges that split the model's polygons into triangles (#D by 2 vertex ids),
    /// which q_min does not bind, replacing those marked before
    /// (vsr_mesh_set_polygon_diagonals).
    Mesh &set_polygon_diagonals(const std::vector<std::uint32_t> &diagonals) {
        check(try_set_polygon_diagonals(diagonals.data(),
                                        detail::rows(diagonals.size(), 2, "diagonals")));
        return *this;
    }
    [[nodiscard]] VsrStatus try_set_polygon_diagonals(const std::uint32_t *diagonals,
                                                      std::size_t n_diagonals) noexcept {
        return vsr_mesh_set_polygon_diagonals(get(), diagonals, n_diagonals);
    }

    /// Weight per unit area of each face (#F values).
    Mesh &face_density(const std::vector<double> &density) {
        check(try_face_density(density.data(), density.size()));
        return *this;
    }
    [[nodiscard]] VsrStatus try_face_density(const double *density, std::size_t n) noexcept {
        return vsr_mesh_set_face_density(get(), density, n);
    }
    /// Extra vertical load per vertex (#V values, downward positive).
    Mesh &extra_loads(const std::vector<double> &loads) {
        check(try_extra_loads(loads.data(), loads.size()));
        return *this;
    }
    [[nodiscard]] VsrStatus try_extra_loads(const double *loads, std::size_t n) noexcept {
        return vsr_mesh_set_extra_loads(get(), loads, n);
    }
    /// Prescribed horizontal force per vertex (#V by 2 values).
    Mesh &horizontal_forces(const std::vector<double> &forces) {
        check(try_horizontal_forces(forces.data(), detail::rows(forces.size(), 2, "forces")));
        return *this;
    }
    [[nodiscard]] VsrStatus try_horizontal_forces(const double *forces,
                                                  std::size_t n_vertices) noexcept {
        return vsr_mesh_set_horizontal_forces(get(), forces, n_vertices);
    }
    /// Prescribed τ per vertex (#V values), used with VSR_TAU_MODE_PRESCRIBED.
    Mesh &prescribed_tau(const std::vector<double> &tau) {
        check(try_prescribed_tau(tau.data(), tau.size()));
        return *this;
    }
    [[nodiscard]] VsrStatus try_prescribed_tau(const double *tau, std::size_t n) noexcept {
        return vsr_mesh_set_prescribed_tau(get(), tau, n);
    }

  private:
    detail::Owner<VsrMesh, vsr_mesh_destroy> owner_;
};

// One fluent setter over vsr_settings_set_<name> and its try_ twin.
#define VOUSSOIR_DETAIL_SETTER(name, Type)                    \
    Settings &name(Type value) {                              \
        check(try_##name(value));                             \
        return *this;                                         \
    }                                                         \
    [[nodiscard]] VsrStatus try_##name(Type value) noexcept { \
        return vsr_settings_set_##name(get(), value);         \
    }

/// Solver options with the C API's defaults (vsr_settings_create), set fluently:
/// `settings.tolerance(1e-8).max_iterations(200)`. Each setter throws Error and keeps the
/// previous value when the new one is rejected; try_<name> returns the status instead.
class Settings {
  public:
    /// The defaults. Throws Error (only when the library cannot allocate).
    Settings() {
        VsrSettings *raw = nullptr;
        check(vsr_settings_create(&raw));
        owner_.reset(raw);
    }
    /// Adopts a handle from vsr_settings_create (NULL: an empty Settings). No release():
    /// the handle may point at the progress function these settings own.
    explicit Settings(VsrSettings *handle) noexcept : owner_(handle) {}
    Settings(Settings &&) noexcept = default;
    Settings &operator=(Settings &&) noexcept = default;

    VsrSettings *get() const noexcept { return owner_.get(); }
    explicit operator bool() const noexcept { return static_cast<bool>(owner_); }

    VOUSSOIR_DETAIL_SETTER(tolerance, double)
    VOUSSOIR_DETAIL_SETTER(max_iterations, std::size_t)
    VOUSSOIR_DETAIL_SETTER(stall_window, std::size_t)
    VOUSSOIR_DETAIL_SETTER(q_min_scope, VsrEdgeScope)
    VOUSSOIR_DETAIL_SETTER(tau_mode, VsrTauMode)
    VOUSSOIR_DETAIL_SETTER(hole_mode, VsrHoleMode)
    VOUSSOIR_DETAIL_SETTER(method, VsrMethod)
    VOUSSOIR_DETAIL_SETTER(fairness, double)
    VOUSSOIR_DETAIL_SETTER(max_height_change, double)
    VOUSSOIR_DETAIL_SETTER(load_rule, VsrLoadRule)
    VOUSSOIR_DETAIL_SETTER(formulation, VsrFormulation)
    VOUSSOIR_DETAIL_SETTER(qp_solver, VsrQpSolver)
    VOUSSOIR_DETAIL_SETTER(regularisation, double)
    VOUSSOIR_DETAIL_SETTER(schedule_mu0, double)
    VOUSSOIR_DETAIL_SETTER(schedule_beta, double)
    VOUSSOIR_DETAIL_SETTER(schedule_mu_min, double)
    VOUSSOIR_DETAIL_SETTER(schedule_eta, double)
    VOUSSOIR_DETAIL_SETTER(schedule_pull, double)
    VOUSSOIR_DETAIL_SETTER(proximal_weight, double)
    VOUSSOIR_DETAIL_SETTER(odt_iterations, std::size_t)

    Settings &q_min(double value, VsrBoundKind kind) {
        check(try_q_min(value, kind));
        return *this;
    }
    [[nodiscard]] VsrStatus try_q_min(double value, VsrBoundKind kind) noexcept {
        return vsr_settings_set_q_min(get(), value, kind);
    }
    Settings &q_max(double value, VsrBoundKind kind) {
        check(try_q_max(value, kind));
        return *this;
    }
    [[nodiscard]] VsrStatus try_q_max(double value, VsrBoundKind kind) noexcept {
        return vsr_settings_set_q_max(get(), value, kind);
    }
    Settings &dual_length_bounds(double lo, double hi) {
        check(try_dual_length_bounds(lo, hi));
        return *this;
    }
    [[nodiscard]] VsrStatus try_dual_length_bounds(double lo, double hi) noexcept {
        return vsr_settings_set_dual_length_bounds(get(), lo, hi);
    }
    Settings &dual_length_smoothing(double mu, double decay) {
        check(try_dual_length_smoothing(mu, decay));
        return *this;
    }
    [[nodiscard]] VsrStatus try_dual_length_smoothing(double mu, double decay) noexcept {
        return vsr_settings_set_dual_length_smoothing(get(), mu, decay);
    }
    Settings &odt_free_boundary(bool enable) {
        check(try_odt_free_boundary(enable));
        return *this;
    }
    [[nodiscard]] VsrStatus try_odt_free_boundary(bool enable) noexcept {
        return vsr_settings_set_odt_free_boundary(get(), enable ? 1u : 0u);
    }

    /// Sets the progress callback of form_find (an empty function removes it). The settings
    /// keep the function; it is called on the solving thread.
    Settings &progress(ProgressFn callback) {
        auto fn = callback ? std::make_unique<ProgressFn>(std::move(callback)) : nullptr;
        check(
            vsr_settings_set_progress(get(), fn ? detail::progress_trampoline : nullptr, fn.get()));
        progress_ = std::move(fn);
        return *this;
    }

  private:
    detail::Owner<VsrSettings, vsr_settings_destroy> owner_;
    std::unique_ptr<ProgressFn> progress_;  // heap: its address survives moves
};

#undef VOUSSOIR_DETAIL_SETTER

/// vsr_result_stress_summary.
struct StressSummary {
    VsrStressStatus status = VSR_STRESS_STATUS_NUMERICAL_ERROR;
    double eps_inf = 0, objective = 0;
    std::size_t qp_iterations = 0;
};
/// vsr_result_termination.
struct Termination {
    VsrTermination reason = VSR_TERMINATION_NUMERICAL_ERROR;
    std::size_t iterations = 0;
    bool converged() const noexcept { return reason == VSR_TERMINATION_CONVERGED; }
};
/// vsr_result_height_change: over the plan diagonal.
struct HeightChange {
    double rms = 0, max = 0;
};
/// vsr_result_distances: over the plan diagonal.
struct Distances {
    double hausdorff = 0, l2 = 0;
};
/// vsr_result_timings: wall-clock seconds.
struct Timings {
    double stress = 0, shape = 0, total = 0;
};

/// The outcome of analyse or form_find (VsrResult): immutable, every getter is const.
class Result {
  public:
    Result() noexcept = default;
    /// Adopts a handle from vsr_analyse / vsr_form_find (NULL: an empty Result).
    explicit Result(VsrResult *handle) noexcept : owner_(handle) {}

    VsrResult *get() const noexcept { return owner_.get(); }
    VsrResult *release() noexcept { return owner_.release(); }
    explicit operator bool() const noexcept { return static_cast<bool>(owner_); }

    VsrResultKind kind() const {
        VsrResultKind k = VSR_RESULT_KIND_ANALYSIS;
        check(vsr_result_kind(get(), &k));
        return k;
    }
    Counts counts() const {
        Counts c;
        check(vsr_result_counts(get(), &c.vertices, &c.edges, &c.faces, &c.holes));
        return c;
    }

    VOUSSOIR_DETAIL_GETTER(double, positions, vsr_result_positions, VsrResult)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, edges, vsr_result_edges, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, force_densities, vsr_result_force_densities, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, airy, vsr_result_airy, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, weights, vsr_result_weights, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, tau, vsr_result_tau, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, external_horizontal, vsr_result_external_horizontal, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, loads, vsr_result_loads, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, residuals, vsr_result_residuals, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, horizontal_imbalance, vsr_result_horizontal_imbalance, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, hole_coefficients, vsr_result_hole_coefficients, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, force_diagram_centres, vsr_result_force_diagram_centres,
                           VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, force_diagram_segments, vsr_result_force_diagram_segments,
                           VsrResult)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, force_diagram_segment_edges,
                           vsr_result_force_diagram_segment_edges, VsrResult)
    VOUSSOIR_DETAIL_GETTER(double, eps_history, vsr_result_eps_history, VsrResult)
    VOUSSOIR_DETAIL_GETTER(VsrQpSolver, step_solvers, vsr_result_step_solvers, VsrResult)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, stalled_vertices, vsr_result_stalled_vertices, VsrResult)

    StressSummary stress_summary() const {
        StressSummary s;
        check(vsr_result_stress_summary(get(), &s.status, &s.eps_inf, &s.objective,
                                        &s.qp_iterations));
        return s;
    }
    double regularisation() const {
        double eps = 0;
        check(vsr_result_regularisation(get(), &eps));
        return eps;
    }
    VsrQpSolver qp_solver() const {
        VsrQpSolver solver = VSR_QP_SOLVER_NATIVE;
        check(vsr_result_qp_solver(get(), &solver));
        return solver;
    }
    /// Form finding only (VSR_STATUS_NOT_AVAILABLE for an analysis).
    Termination termination() const {
        Termination t;
        check(vsr_result_termination(get(), &t.reason, &t.iterations));
        return t;
    }
    std::string termination_message() const {
        std::vector<char> text;
        detail::copy_into<char, VsrResult>(vsr_result_termination_message, get(), text);
        return text.empty() ? std::string() : std::string(text.data());
    }
    HeightChange height_change() const {
        HeightChange h;
        check(vsr_result_height_change(get(), &h.rms, &h.max));
        return h;
    }
    /// Form finding only: whether the input hung and was read upside down (method.md 13.1).
    bool mirrored() const {
        int32_t m = 0;
        check(vsr_result_mirrored(get(), &m));
        return m != 0;
    }
    Distances distances() const {
        Distances d;
        check(vsr_result_distances(get(), &d.hausdorff, &d.l2));
        return d;
    }
    Timings timings() const {
        Timings t;
        check(vsr_result_timings(get(), &t.stress, &t.shape, &t.total));
        return t;
    }

    /// Writes the positions with `mesh`'s triangles (.obj, .off, .ply, .stl), all or nothing.
    void write(const Mesh &mesh, const std::string &path) const { check(try_write(mesh, path)); }
    [[nodiscard]] VsrStatus try_write(const Mesh &mesh, const std::string &path) const noexcept {
        return vsr_result_write(get(), mesh.get(), path.c_str());
    }
    /// Writes the result thickened into a printable solid (vsr_result_write_solid). Throws Error.
    void write_solid(const Mesh &mesh, double thickness, const std::string &path) const {
        check(try_write_solid(mesh, thickness, path));
    }
    [[nodiscard]] VsrStatus try_write_solid(const Mesh &mesh, double thickness,
                                            const std::string &path) const noexcept {
        return vsr_result_write_solid(get(), mesh.get(), thickness, path.c_str());
    }
    /// The same with the thickness per face from its density: density / `unit_weight`
    /// (vsr_result_write_solid_from_density). Throws Error.
    void write_solid_from_density(const Mesh &mesh, double unit_weight,
                                  const std::string &path) const {
        check(try_write_solid_from_density(mesh, unit_weight, path));
    }
    [[nodiscard]] VsrStatus try_write_solid_from_density(const Mesh &mesh, double unit_weight,
                                                         const std::string &path) const noexcept {
        return vsr_result_write_solid_from_density(get(), mesh.get(), unit_weight, path.c_str());
    }

  private:
    detail::Owner<VsrResult, vsr_result_destroy> owner_;
};

// ---------------------------------------------------------------------------------------------
// Masonry assessment: a thrust surface inside the masonry (vsr_assess).

/// The masonry between intrados and extrados over a mesh's plan (VsrEnvelope): per vertex a
/// lower and an upper height, per face the thickness whose weight loads the vault.
class Envelope {
  public:
    Envelope() noexcept = default;
    /// Adopts a handle from vsr_envelope_from_* (NULL: an empty Envelope).
    explicit Envelope(VsrEnvelope *handle) noexcept : owner_(handle) {}

    /// A uniform (one value) or per-face (#F values) thickness about the mesh as middle
    /// surface, along its normals (vsr_envelope_from_thickness). Throws Error.
    static Envelope from_thickness(const Mesh &mesh, const std::vector<double> &thickness) {
        Envelope e;
        check(try_from_thickness(mesh, thickness.data(), thickness.size(), e));
        return e;
    }
    static Envelope from_thickness(const Mesh &mesh, double thickness) {
        return from_thickness(mesh, std::vector<double>{thickness});
    }
    [[nodiscard]] static VsrStatus try_from_thickness(const Mesh &mesh, const double *thickness,
                                                      std::size_t n, Envelope &out) noexcept {
        VsrEnvelope *raw = nullptr;
        const VsrStatus status = vsr_envelope_from_thickness(mesh.get(), thickness, n, &raw);
        if (status == VSR_STATUS_OK) out.owner_.reset(raw);
        return status;
    }

    /// Intrados and extrados as triangle surfaces (#V by 3 positions, #F by 3 triangles each,
    /// any triangulation), sampled over the mesh's vertices (vsr_envelope_from_surfaces).
    /// Throws Error.
    static Envelope from_surfaces(const Mesh &mesh, const std::vector<double> &intrados,
                                  const std::vector<std::uint32_t> &intrados_triangles,
                                  const std::vector<double> &extrados,
                                  const std::vector<std::uint32_t> &extrados_triangles) {
        Envelope e;
        check(try_from_surfaces(
            mesh, intrados.data(), detail::rows(intrados.size(), 3, "intrados"),
            intrados_triangles.data(),
            detail::rows(intrados_triangles.size(), 3, "intrados_triangles"), extrados.data(),
            detail::rows(extrados.size(), 3, "extrados"), extrados_triangles.data(),
            detail::rows(extrados_triangles.size(), 3, "extrados_triangles"), e));
        return e;
    }
    [[nodiscard]] static VsrStatus try_from_surfaces(
        const Mesh &mesh, const double *intrados, std::size_t n_intrados_vertices,
        const std::uint32_t *intrados_triangles, std::size_t n_intrados_triangles,
        const double *extrados, std::size_t n_extrados_vertices,
        const std::uint32_t *extrados_triangles, std::size_t n_extrados_triangles,
        Envelope &out) noexcept {
        VsrEnvelope *raw = nullptr;
        const VsrStatus status = vsr_envelope_from_surfaces(
            mesh.get(), intrados, n_intrados_vertices, intrados_triangles, n_intrados_triangles,
            extrados, n_extrados_vertices, extrados_triangles, n_extrados_triangles, &raw);
        if (status == VSR_STATUS_OK) out.owner_.reset(raw);
        return status;
    }

    VsrEnvelope *get() const noexcept { return owner_.get(); }
    VsrEnvelope *release() noexcept { return owner_.release(); }
    explicit operator bool() const noexcept { return static_cast<bool>(owner_); }

    VOUSSOIR_DETAIL_GETTER(double, lower, vsr_envelope_lower, VsrEnvelope)
    VOUSSOIR_DETAIL_GETTER(double, upper, vsr_envelope_upper, VsrEnvelope)
    VOUSSOIR_DETAIL_GETTER(double, face_thickness, vsr_envelope_face_thickness, VsrEnvelope)
    /// Springing plane's height and joint's reach per vertex, read at free supports
    /// (vsr_envelope_springing, vsr_envelope_reach; INFINITY: no joint).
    VOUSSOIR_DETAIL_GETTER(double, springing, vsr_envelope_springing, VsrEnvelope)
    VOUSSOIR_DETAIL_GETTER(double, reach, vsr_envelope_reach, VsrEnvelope)

    /// Sets the springing joints of free supports, one value per vertex each
    /// (vsr_envelope_set_springing): the plane's height and the joint's reach, INFINITY for
    /// no joint (the support's height bounded by the envelope alone). Throws Error naming
    /// the argument and vertex; the envelope is unchanged then.
    Envelope &set_springing(const std::vector<double> &springing,
                            const std::vector<double> &reach) {
        check(try_set_springing(springing.data(), springing.size(), reach.data(), reach.size()));
        return *this;
    }
    [[nodiscard]] VsrStatus try_set_springing(const double *springing, std::size_t n_springing,
                                              const double *reach,
                                              std::size_t n_reach) noexcept {
        return vsr_envelope_set_springing(get(), springing, n_springing, reach, n_reach);
    }

  private:
    detail::Owner<VsrEnvelope, vsr_envelope_destroy> owner_;
};

// One fluent setter over vsr_assess_settings_set_<name> and its try_ twin.
#define VOUSSOIR_DETAIL_ASSESS_SETTER(name, Type)             \
    AssessSettings &name(Type value) {                        \
        check(try_##name(value));                             \
        return *this;                                         \
    }                                                         \
    [[nodiscard]] VsrStatus try_##name(Type value) noexcept { \
        return vsr_assess_settings_set_##name(get(), value);  \
    }

/// Options of assess with the C API's defaults (vsr_assess_settings_create), set fluently:
/// `settings.objective(VSR_OBJECTIVE_MIN_THICKNESS).unit_weight(20)`. Each setter throws
/// Error and keeps the previous value when the new one is rejected; try_<name> returns the
/// status instead.
class AssessSettings {
  public:
    /// The defaults. Throws Error (only when the library cannot allocate).
    AssessSettings() {
        VsrAssessSettings *raw = nullptr;
        check(vsr_assess_settings_create(&raw));
        owner_.reset(raw);
    }
    AssessSettings(AssessSettings &&) noexcept = default;
    AssessSettings &operator=(AssessSettings &&) noexcept = default;

    VsrAssessSettings *get() const noexcept { return owner_.get(); }
    explicit operator bool() const noexcept { return static_cast<bool>(owner_); }

    VOUSSOIR_DETAIL_ASSESS_SETTER(objective, VsrObjective)
    VOUSSOIR_DETAIL_ASSESS_SETTER(unit_weight, double)
    VOUSSOIR_DETAIL_ASSESS_SETTER(load_rule, VsrLoadRule)
    VOUSSOIR_DETAIL_ASSESS_SETTER(tolerance, double)
    VOUSSOIR_DETAIL_ASSESS_SETTER(max_iterations, std::size_t)

    AssessSettings &fixed_supports(bool fixed) {
        check(try_fixed_supports(fixed));
        return *this;
    }
    [[nodiscard]] VsrStatus try_fixed_supports(bool fixed) noexcept {
        return vsr_assess_settings_set_fixed_supports(get(), fixed ? 1u : 0u);
    }
    /// The live load of max-load, one value per mesh vertex (empty: none).
    AssessSettings &load_pattern(const std::vector<double> &loads) {
        check(try_load_pattern(loads.data(), loads.size()));
        return *this;
    }
    [[nodiscard]] VsrStatus try_load_pattern(const double *loads, std::size_t n) noexcept {
        return vsr_assess_settings_set_load_pattern(get(), loads, n);
    }
    AssessSettings &q_min(double value, VsrBoundKind kind) {
        check(try_q_min(value, kind));
        return *this;
    }
    [[nodiscard]] VsrStatus try_q_min(double value, VsrBoundKind kind) noexcept {
        return vsr_assess_settings_set_q_min(get(), value, kind);
    }
    /// Called once per step with the step (1-based) and the infeasibility of the state
    /// reached; Cancel stops the search (VSR_TERMINATION_CANCELLED). An empty function
    /// removes it; an exception it throws cancels and is rethrown by assess.
    AssessSettings &progress(ProgressFn callback) {
        auto fn = callback ? std::make_unique<ProgressFn>(std::move(callback)) : nullptr;
        check(vsr_assess_settings_set_progress(get(), fn ? detail::progress_trampoline : nullptr,
                                               fn.get()));
        progress_ = std::move(fn);
        return *this;
    }

  private:
    detail::Owner<VsrAssessSettings, vsr_assess_settings_destroy> owner_;
    std::unique_ptr<ProgressFn> progress_;  // heap: its address survives moves
};

#undef VOUSSOIR_DETAIL_ASSESS_SETTER

/// vsr_assessment_outcome.
struct AssessmentOutcome {
    bool feasible = false;
    VsrTermination termination = VSR_TERMINATION_NUMERICAL_ERROR;
    std::size_t iterations = 0;
    double seconds = 0;
    /// A certified thrust surface, optimal for the objective.
    bool converged() const noexcept {
        return feasible && termination == VSR_TERMINATION_CONVERGED;
    }
};
/// vsr_assessment_figures.
struct AssessmentFigures {
    double thickness_scale = 1, safety_factor = 1, thrust_horizontal = 0, load_factor = 0;
};
/// vsr_assessment_certificate; vertices are VSR_NO_VERTEX where there is none.
struct Certificate {
    double eps_inf = 0, horizontal_imbalance = 0, worst_bound = 0;
    std::uint32_t worst_bound_vertex = VSR_NO_VERTEX, worst_residual_vertex = VSR_NO_VERTEX;
};
/// vsr_assessment_worst_joint; vertex is VSR_NO_VERTEX where there is none.
struct WorstJoint {
    double excess = 0;
    std::uint32_t vertex = VSR_NO_VERTEX;
};

/// The outcome of assess (VsrAssessment): immutable, every getter is const.
class Assessment {
  public:
    Assessment() noexcept = default;
    /// Adopts a handle from vsr_assess (NULL: an empty Assessment).
    explicit Assessment(VsrAssessment *handle) noexcept : owner_(handle) {}

    VsrAssessment *get() const noexcept { return owner_.get(); }
    VsrAssessment *release() noexcept { return owner_.release(); }
    explicit operator bool() const noexcept { return static_cast<bool>(owner_); }

    VOUSSOIR_DETAIL_GETTER(double, positions, vsr_assessment_positions, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, edges, vsr_assessment_edges, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(double, force_densities, vsr_assessment_force_densities, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(double, loads, vsr_assessment_loads, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(double, residuals, vsr_assessment_residuals, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(double, lower, vsr_assessment_lower, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(double, upper, vsr_assessment_upper, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(double, reactions, vsr_assessment_reactions, VsrAssessment)
    /// #J by 9 per springing joint (vsr_assessment_joints); its supports: joint_vertices.
    VOUSSOIR_DETAIL_GETTER(double, joints, vsr_assessment_joints, VsrAssessment)
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, joint_vertices, vsr_assessment_joint_vertices,
                           VsrAssessment)
    /// The vertices with no compressive path to a support (vsr_assessment_stranded).
    VOUSSOIR_DETAIL_GETTER(std::uint32_t, stranded, vsr_assessment_stranded, VsrAssessment)

    VsrObjective objective() const {
        VsrObjective o = VSR_OBJECTIVE_FIT;
        check(vsr_assessment_objective(get(), &o));
        return o;
    }
    AssessmentOutcome outcome() const {
        AssessmentOutcome o;
        std::uint32_t feasible = 0;
        check(vsr_assessment_outcome(get(), &feasible, &o.termination, &o.iterations,
                                     &o.seconds));
        o.feasible = feasible != 0;
        return o;
    }
    AssessmentFigures figures() const {
        AssessmentFigures f;
        check(vsr_assessment_figures(get(), &f.thickness_scale, &f.safety_factor,
                                     &f.thrust_horizontal, &f.load_factor));
        return f;
    }
    Certificate certificate() const {
        Certificate c;
        check(vsr_assessment_certificate(get(), &c.eps_inf, &c.horizontal_imbalance,
                                         &c.worst_bound, &c.worst_bound_vertex,
                                         &c.worst_residual_vertex));
        return c;
    }
    /// max-thrust, max-load: the objective has no bound (vsr_assessment_unbounded).
    bool unbounded() const {
        std::uint32_t unbounded = 0;
        check(vsr_assessment_unbounded(get(), &unbounded));
        return unbounded != 0;
    }
    WorstJoint worst_joint() const {
        WorstJoint w;
        check(vsr_assessment_worst_joint(get(), &w.excess, &w.vertex));
        return w;
    }
    std::string termination_message() const {
        std::vector<char> text;
        detail::copy_into<char, VsrAssessment>(vsr_assessment_termination_message, get(), text);
        return text.empty() ? std::string() : std::string(text.data());
    }

  private:
    detail::Owner<VsrAssessment, vsr_assessment_destroy> owner_;
};

#undef VOUSSOIR_DETAIL_GETTER

/// Stress analysis of the mesh as given (vsr_analyse). Throws Error.
[[nodiscard]] inline VsrStatus try_analyse(const Mesh &mesh, const Settings &settings,
                                           Result &out) noexcept {
    VsrResult *raw = nullptr;
    const VsrStatus status = vsr_analyse(mesh.get(), settings.get(), &raw);
    if (status == VSR_STATUS_OK) out = Result(raw);
    return status;
}
inline Result analyse(const Mesh &mesh, const Settings &settings = Settings()) {
    Result result;
    check(try_analyse(mesh, settings, result));
    return result;
}

/// Form finding (vsr_form_find). The try_ twin returns the status; an exception thrown by
/// the progress callback cancels the solve and then propagates from form_find (try_form_find
/// returns VSR_STATUS_OK with a cancelled result and drops the exception).
[[nodiscard]] inline VsrStatus try_form_find(const Mesh &mesh, const Settings &settings,
                                             Result &out) noexcept {
    VsrResult *raw = nullptr;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_form_find(mesh.get(), settings.get(), &raw);
    detail::progress_exception() = nullptr;
    if (status == VSR_STATUS_OK) out = Result(raw);
    return status;
}
inline Result form_find(const Mesh &mesh, const Settings &settings = Settings()) {
    VsrResult *raw = nullptr;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_form_find(mesh.get(), settings.get(), &raw);
    Result result(raw);
    if (std::exception_ptr thrown = std::exchange(detail::progress_exception(), nullptr))
        std::rethrow_exception(thrown);
    check(status);
    return result;
}

/// Form finding after a small edit, started from `previous` (vsr_form_find_from): the same
/// answer as form_find(mesh, settings), in fewer stress steps where `mesh` differs from the
/// one `previous` was found on by a few heights, supports, loads or settings (same vertices
/// and triangles; not the paper's loop). `previous` stays valid. Errors and the progress
/// callback as form_find; the try_ twin returns the status.
[[nodiscard]] inline VsrStatus try_form_find_from(const Mesh &mesh, const Settings &settings,
                                                  const Result &previous, Result &out) noexcept {
    VsrResult *raw = nullptr;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_form_find_from(mesh.get(), settings.get(), previous.get(), &raw);
    detail::progress_exception() = nullptr;
    if (status == VSR_STATUS_OK) out = Result(raw);
    return status;
}
inline Result form_find_from(const Mesh &mesh, const Settings &settings,
                             const Result &previous) {
    VsrResult *raw = nullptr;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_form_find_from(mesh.get(), settings.get(), previous.get(), &raw);
    Result result(raw);
    if (std::exception_ptr thrown = std::exchange(detail::progress_exception(), nullptr))
        std::rethrow_exception(thrown);
    check(status);
    return result;
}

/// Masonry assessment (vsr_assess): a compression-only thrust surface in equilibrium with the
/// envelope's self-weight, between intrados and extrados, optimal for the settings'
/// objective. A search that certifies none is not an error: read Assessment::outcome().
/// The try_ twin returns the status; an exception thrown by the progress callback cancels
/// the search and then propagates from assess (try_assess drops it).
[[nodiscard]] inline VsrStatus try_assess(const Mesh &mesh, const Envelope &envelope,
                                          const AssessSettings &settings,
                                          Assessment &out) noexcept {
    VsrAssessment *raw = nullptr;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_assess(mesh.get(), envelope.get(), settings.get(), &raw);
    detail::progress_exception() = nullptr;
    if (status == VSR_STATUS_OK) out = Assessment(raw);
    return status;
}
inline Assessment assess(const Mesh &mesh, const Envelope &envelope,
                         const AssessSettings &settings = AssessSettings()) {
    VsrAssessment *raw = nullptr;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_assess(mesh.get(), envelope.get(), settings.get(), &raw);
    Assessment assessment(raw);
    if (std::exception_ptr thrown = std::exchange(detail::progress_exception(), nullptr))
        std::rethrow_exception(thrown);
    check(status);
    return assessment;
}

/// The least thickness of a family of envelopes (vsr_min_thickness_of_family): `bounds(t,
/// lower, upper)` fills the intrados and extrados heights of thickness t, one per vertex
/// (both vectors come sized); the self-weight is area x t x the settings' unit weight.
struct FamilyThickness {
    double thickness = 0;
    bool converged = false;
    Assessment assessment;
};
using FamilyBoundsFn = std::function<void(double, std::vector<double> &, std::vector<double> &)>;

namespace detail {
struct FamilyCall {
    const FamilyBoundsFn *bounds;
    std::vector<double> lower, upper;
};
inline int family_trampoline(void *user, double t, double *lower, double *upper,
                             std::size_t n) {
    auto &call = *static_cast<FamilyCall *>(user);
    try {
        call.lower.assign(n, 0.0);
        call.upper.assign(n, 0.0);
        (*call.bounds)(t, call.lower, call.upper);
        if (call.lower.size() != n || call.upper.size() != n)
            throw Error(VSR_STATUS_INVALID_ARGUMENT,
                        "`bounds` resized its vectors: give one value per vertex");
        std::copy(call.lower.begin(), call.lower.end(), lower);
        std::copy(call.upper.begin(), call.upper.end(), upper);
        return 0;
    } catch (...) {
        // Nothing may unwind through the C library: keep the exception and stop.
        progress_exception() = std::current_exception();
        return 1;
    }
}
}  // namespace detail

/// Throws Error, or rethrows what `bounds` threw.
inline FamilyThickness min_thickness_of_family(const Mesh &mesh, const FamilyBoundsFn &bounds,
                                               double thickness, double scale_tolerance = 1e-3,
                                               const AssessSettings &settings = AssessSettings()) {
    detail::FamilyCall call{&bounds, {}, {}};
    VsrAssessment *raw = nullptr;
    FamilyThickness out;
    int converged = 0;
    detail::progress_exception() = nullptr;
    const VsrStatus status = vsr_min_thickness_of_family(
        mesh.get(), detail::family_trampoline, &call, thickness, scale_tolerance, settings.get(),
        &raw, &out.thickness, &converged);
    out.assessment = Assessment(raw);
    if (std::exception_ptr thrown = std::exchange(detail::progress_exception(), nullptr))
        std::rethrow_exception(thrown);
    check(status);
    out.converged = converged != 0;
    return out;
}

}  // namespace voussoir

#endif  // VOUSSOIR_HPP
