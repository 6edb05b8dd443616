//! Command-line options, parsed with lexopt and validated before any file is read.

use std::path::PathBuf;
use std::str::FromStr;

use crate::assess::args::AssessOptions;
use voussoir::io::{ReadOptions, Supports, UpAxis};
use voussoir::{
    EdgeScope, FormFindSettings, FormMethod, Formulation, HoleMode, LoadRule, QBound, QpSolver,
    TauMode,
};

/// The names of `all`, as the library spells them (`voussoir`'s `as_str`), joined by `sep`.
fn names<T: std::fmt::Display>(all: &[T], sep: &str) -> String {
    let names: Vec<String> = all.iter().map(|v| v.to_string()).collect();
    names.join(sep)
}

/// A bound as typed on the command line: `X` (relative) or `Xabs`.
pub fn bound_text(b: Option<QBound>) -> String {
    match b {
        None => "none".into(),
        Some(QBound::Relative(v)) => format!("{v}"),
        Some(QBound::Absolute(v)) => format!("{v}abs"),
        Some(other) => format!("{other:?}"),
    }
}

/// `--help`, with the defaults of `FormFindSettings::default()`.
pub fn help() -> String {
    let d = FormFindSettings::default();
    let st = &d.stress;
    format!(
        "\
formfind: the nearest self-supporting (compression-only) shape to a triangulated vault.

Usage:
  formfind                                   form-find the embedded default vault
  formfind MESH.obj --supports S.json [options]
  formfind MESH.obj --anchor-boundary [options]
  formfind MESH.off --anchor-lowest 0.01 --out OUT.ply [options]
  formfind MESH.obj --supports S.json --solid 0.1 SOLID.3mf [options]

Inputs:
  MESH                   .obj, .off, .stl or .ply: vertices (x, y plan; z up) and faces;
                         polygons are split into fans, whose diagonals --qmin
                         does not bind
  --supports S.json      anchored vertex ids, 0-based ids of MESH's own vertices (before
                         welding): {{\"anchored\": [ids]}} or [ids]
  --anchor-boundary      anchor every boundary vertex (instead of --supports)
  --anchor-lowest TOL    anchor every vertex within TOL of the lowest height; TOL is
                         relative to the bounding box diagonal, or TOLabs absolute
  --weld TOL             merge vertices closer than TOL x the bounding box diagonal; the
                         mesh is then numbered in first-occurrence order     [{weld:e}]
  --up A                 z | y: the axis that points up in MESH; y for the Y-up files
                         most modellers export (OUT keeps MESH's axes)       [z]
  --strict               reject plan slivers (faces of almost no plan area, or slightly
                         inverted) instead of mending them by edge flips or the smallest
                         plan move of a non-anchored vertex (listed in the report)
  --no-weld              keep MESH's vertices as they are (not for STL, whose triangles
                         never share vertices)

Outputs (checked before the run; all written at the end of it, or none; existing files
are replaced only when every output is written; two outputs may not share a path):
  --out OUT              final positions, same faces (after any plan repair), in the
                         format of the extension: .obj, .off, .ply (every bit kept) or
                         .stl (single precision)
                                                        [formfind-out/NAME-formfound.obj]
  --report R.json        everything computed, as JSON   [formfind-out/report.json]
  --pictures DIR         SVG pictures                   [formfind-out/pictures]
                         plan_forces, force_diagram, residuals, height_change
                         (not with --stress-only) and shape_3d.svg: the input
                         and the form-found shape side by side, seen from
                         azimuth −60° and 30° above the horizon, shaded, the
                         faces coloured by height change; about 70 bytes per
                         face and view (14 MB for 100k faces). With --assess:
                         plan_forces, section.svg (a vertical section: intrados,
                         extrados, the thrust surface and the supports) and
                         shape_3d.svg (the middle surface; the thrust surface,
                         coloured by where it lies between intrados and
                         extrados, under the translucent extrados)
  --solid T OUT          also a printable solid: the result thickened by T (half above,
                         half below, along vertex normals), closed by walls along every
                         boundary; OUT is .stl, .3mf (read as millimetres), .off, .obj or
                         .ply. T is a length in the mesh's units, or `density`: --density
                         / --solid-unit-weight. Exit 2 (nothing written) if T is so large
                         that the solid would intersect itself (the message names where,
                         and the largest T that fits there)
  --solid-unit-weight W  weight per unit volume, for --solid density
  --ascii                write STL and PLY outputs as ASCII text, not binary
  Without MESH, the embedded input is also written next to OUT, as NAME-input.obj
  and NAME-supports.json, to try other options on.

Assessment (instead of form finding; MESH is the masonry's middle surface):
  --assess A             fit | min-thickness | min-thrust | max-thrust | max-load: find a
                         compression-only thrust surface in equilibrium with the masonry's
                         self-weight between intrados and extrados, over MESH's plan (by
                         Heyman's safe theorem the vault then stands): fit, the one nearest
                         the middle surface; min-thickness, the least uniform scale s of the
                         thickness that still holds one (safety factor 1/s); min-thrust and
                         max-thrust, the least and greatest horizontal thrust at the
                         supports; max-load, the largest factor on --load-pattern. OUT is
                         the thrust surface; the report's \"assessment\" holds the figures
  --thickness T          the masonry's thickness along MESH's normals, half above, half below
                         (read vertically as T / (2 n_z)); or `density`: --density / W
  --intrados A           instead of --thickness: the intrados and the extrados as meshes
  --extrados B           (.obj, .off, .stl, .ply), sampled on the vertical through each vertex
  --unit-weight W        weight per unit volume: self-weight = area x thickness x W      [1]
  --fixed-supports       keep the supports at MESH's heights (by default the thrust meets
                         each support anywhere within the envelope)
  --springing Z          free supports: the springing plane's height at every support; the
                         support lies on or above it, and its reaction's line of action,
                         followed down to it, meets it within the reach   [the intrados,
                         or the middle surface's height with --thickness]
  --reach B              free supports: the springing joint's reach (half its width), a
                         length, at every support; `inf`: no joint, the support's height
                         bounded by the envelope alone   [half the vertex's thickness, read
                         horizontally: T / (2 |n_h|) with --thickness]
  --load-pattern L.json  max-load: a downward load per vertex of MESH (ids before welding;
                         loads of merged vertices add): {{\"loads\": [..]}}, [..] or
                         {{\"loads\": {{\"ID\": load, ..}}}}
  --section S            the section picture's vertical plane: y (through the plan's centre,
                         along x), x, y=VALUE or x=VALUE                                  [y]
  --tol, --max-iter, --qmin and --load apply too [1e-6, 200, 0abs, barycentric]

Solver:
  --stress-only          analyse the input shape only, do not move it
  --method M             {methods}: the nearest self-supporting shape
                         (least area-weighted squared height change), or
                         the paper's loop                                  [{method}]
  --fairness G           nearest method: weight of the change's smoothness [{fairness}]
  --max-height-change H  no vertex moves more than H plan diagonals (either
                         method)                                           [{limit}]
  --solver S             {solvers}                              [{solver}]
  --qp Q                 {qps}: the QP solver (native falls
                         back to clarabel when it does not converge)       [{qp}]
  --tol T                stop when eps_inf = max|r_i| / mean load < T      [{tol:e}]
  --max-iter N           at most N stress steps                            [{max_iter}]
  --qmin X               lower bound on force densities, relative to p/L0
                         (mean load / half the plan diagonal); Xabs is
                         absolute, in force per length, e.g. 2.5abs        [{qmin}]
  --qmin-scope S         {scopes}: the edges --qmin applies to       [{scope}]
  --qmax X               upper bound on force densities, as --qmin, or none [{qmax}]
  --tau M                optimized | zero: normal push at free edges       [{tau}]
  --holes H              {holes_}: how the Airy function jumps
                         around a hole (constant: the paper's, a torque
                         only; its optimum can be worse)                   [{holes}]
  --dual-smoothing MU    penalty MU on differences of force-diagram edge
                         lengths at each face (a smoother force diagram)   [{smooth}]
  --smoothing-decay D    form finding fades MU as MU D^k, 0 <= D < 1;
                         nearer 1: smoother, further from the input        [{decay}]
  --odt N                at most N ODT sweeps of the plan: the nearest method
                         runs them on the input first; the paper method one
                         before each of its first N stress steps; the first
                         sweep that does not improve the plan's triangles
                         is undone and ends them                           [0]
  --density D            weight per unit area of every face                [1]
  --load R               {loads}: how a face's
                         weight is shared among its vertices               [{load}]
  -h, --help             this text

Exit status: 0 converged (or --stress-only solved; with --assess: a certified thrust
surface found and the analysis converged), 3 finished without converging or (--assess) with
no thrust surface inside the envelope, or a least thickness above the given one (outputs
written, the report says why), 2 bad input,
options or output paths (nothing written), 1 other failure (nothing written).
",
        methods = names(FormMethod::ALL, " | "),
        solvers = names(Formulation::ALL, " | "),
        qps = names(QpSolver::ALL, " | "),
        scopes = names(EdgeScope::ALL, " | "),
        holes_ = names(HoleMode::ALL, " | "),
        loads = names(LoadRule::ALL, " | "),
        method = d.method,
        fairness = d.fairness,
        limit = d.max_height_change,
        solver = st.formulation,
        qp = st.solver,
        tol = d.tolerance,
        max_iter = d.max_iterations,
        qmin = bound_text(Some(st.q_min)),
        scope = st.q_min_scope,
        qmax = bound_text(st.q_max),
        tau = st.tau,
        holes = st.holes,
        smooth = st.dual_length_smoothing,
        decay = d.smoothing_decay,
        load = st.load_rule,
        weld = voussoir::io::DEFAULT_WELD_TOLERANCE,
    )
}

/// Everything the command line says.
#[derive(Debug, Clone)]
pub struct Options {
    pub mesh: Option<PathBuf>,
    pub supports: Option<PathBuf>,
    pub anchor_boundary: bool,
    /// `--anchor-lowest`: a tolerance and whether it is absolute.
    pub anchor_lowest: Option<(f64, bool)>,
    /// Relative welding tolerance; `None` for `--no-weld`.
    pub weld: Option<f64>,
    /// `--strict`: no plan repair.
    pub strict: bool,
    /// `--up`: the axis that points up in MESH.
    pub up: UpAxis,
    pub out: Option<PathBuf>,
    pub report: Option<PathBuf>,
    pub pictures: Option<PathBuf>,
    /// `--solid`: the thickness and the output path.
    pub solid: Option<(SolidThickness, PathBuf)>,
    pub solid_unit_weight: Option<f64>,
    /// `--ascii`: STL and PLY outputs as text.
    pub ascii: bool,
    pub stress_only: bool,
    pub odt: Option<usize>,
    pub density: f64,
    pub settings: FormFindSettings,
    /// `--assess` and its options.
    pub assess: AssessOptions,
    /// Every option given, in order (to tell a default from a value given).
    pub given: Vec<String>,
}

/// The thickness of `--solid`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolidThickness {
    /// A length, in the mesh's units.
    Uniform(f64),
    /// Per face, density / unit weight (`--solid density`).
    FromDensity,
}

impl Options {
    /// How the library reads MESH: supports, welding, plan repair and up axis.
    pub fn read_options(&self) -> ReadOptions {
        let supports = if let Some(path) = &self.supports {
            Supports::File(path.clone())
        } else if let Some((tolerance, absolute)) = self.anchor_lowest {
            Supports::Lowest {
                tolerance,
                absolute,
            }
        } else {
            Supports::Boundary
        };
        let repair = if self.strict {
            0.0
        } else {
            voussoir::DEFAULT_REPAIR_TOLERANCE
        };
        ReadOptions::new(supports)
            .with_weld_tolerance(self.weld)
            .with_repair_tolerance(repair)
            .with_up(self.up)
    }

    /// The thickness of the solid, if one is asked for.
    pub fn thickness(&self) -> Option<voussoir::Thickness> {
        match self.solid.as_ref()?.0 {
            SolidThickness::Uniform(t) => Some(voussoir::Thickness::Uniform(t)),
            SolidThickness::FromDensity => {
                let w = self.solid_unit_weight?;
                Some(voussoir::Thickness::Uniform(self.density / w))
            }
        }
    }
}

/// `--solid`'s thickness: a number > 0 or `density`.
fn solid_thickness(text: &str) -> Result<SolidThickness, String> {
    if text == "density" {
        return Ok(SolidThickness::FromDensity);
    }
    match number("--solid", text) {
        Ok(t) if t > 0.0 => Ok(SolidThickness::Uniform(t)),
        _ => Err(format!(
            "--solid: expected a thickness > 0 or `density` before the output path, got `{text}`"
        )),
    }
}

/// What `parse` found: options to run with, or a request for help.
pub enum Parsed {
    Run(Box<Options>),
    Help,
}

pub fn number(flag: &str, text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("{flag}: expected a number, got `{text}`")),
    }
}

/// `X` (relative to p̄/L₀) or `Xabs` (absolute).
fn bound(flag: &str, text: &str) -> Result<QBound, String> {
    let (value, absolute) = match text.strip_suffix("abs") {
        Some(v) => (v, true),
        None => (text, false),
    };
    let v = number(flag, value)
        .map_err(|_| format!("{flag}: expected a number or NUMBERabs, got `{text}`"))?;
    Ok(if absolute {
        QBound::Absolute(v)
    } else {
        QBound::Relative(v)
    })
}

/// `TOL` (relative) or `TOLabs` (absolute); its range is `ReadOptions::validate`'s.
fn tolerance(flag: &str, text: &str) -> Result<(f64, bool), String> {
    let (value, absolute) = match text.strip_suffix("abs") {
        Some(v) => (v, true),
        None => (text, false),
    };
    let v = number(flag, value)
        .map_err(|_| format!("{flag}: expected a number or NUMBERabs, got `{text}`"))?;
    Ok((v, absolute))
}

/// An enumerated option by its library name (`FromStr` of the library's enums).
fn choice<T: FromStr<Err = voussoir::Error>>(flag: &str, text: &str) -> Result<T, String> {
    text.parse().map_err(|e| match e {
        voussoir::Error::InvalidArgument { reason, .. } => format!("{flag}: {reason}"),
        e => format!("{flag}: {e}"),
    })
}

/// Records `flag` in `given`, refusing a second use of it (or of the other spelling of the
/// same setting: `--weld` and `--no-weld`), which would otherwise keep the last value unseen.
fn once(given: &mut Vec<String>, flag: &str) -> Result<(), String> {
    let key = |f: &str| match f {
        "--no-weld" => "--weld".to_string(),
        other => other.to_string(),
    };
    match given.iter().find(|g| key(g) == key(flag)) {
        Some(first) if first == flag => Err(format!("{flag} is given twice; give it once")),
        Some(first) => Err(format!(
            "{first} and {flag} are both given; give one of them"
        )),
        None => {
            given.push(flag.to_string());
            Ok(())
        }
    }
}

/// Parses `args` (without the program name).
pub fn parse(args: impl IntoIterator<Item = std::ffi::OsString>) -> Result<Parsed, String> {
    use lexopt::Arg::{Long, Short, Value};
    let mut parser = lexopt::Parser::from_args(args);
    let mut o = Options {
        mesh: None,
        supports: None,
        anchor_boundary: false,
        anchor_lowest: None,
        weld: Some(voussoir::io::DEFAULT_WELD_TOLERANCE),
        strict: false,
        up: UpAxis::Z,
        out: None,
        report: None,
        pictures: None,
        solid: None,
        solid_unit_weight: None,
        ascii: false,
        stress_only: false,
        odt: None,
        density: 1.0,
        settings: FormFindSettings::default(),
        assess: AssessOptions::default(),
        given: Vec::new(),
    };
    let s = &mut o.settings;
    let mut given: Vec<String> = Vec::new();
    while let Some(arg) = parser.next().map_err(|e| e.to_string())? {
        // Owned copies: `arg` borrows the parser, which `value()` needs.
        let (flag, positional) = match arg {
            Long(name) => (format!("--{name}"), None),
            Short(c) => (format!("-{c}"), None),
            Value(v) => (String::new(), Some(v)),
        };
        let mut value = || -> Result<String, String> {
            let v = parser.value().map_err(|e| e.to_string())?;
            v.into_string()
                .map_err(|v| format!("{flag}: `{}` is not valid text", v.to_string_lossy()))
        };
        if positional.is_none() {
            once(&mut given, &flag)?;
        }
        if let Some(path) = positional {
            if o.mesh.is_some() {
                return Err(format!(
                    "unexpected argument `{}`: only one mesh file is read",
                    path.to_string_lossy()
                ));
            }
            o.mesh = Some(path.into());
            continue;
        }
        o.given.push(flag.clone());
        match flag.as_str() {
            "-h" | "--help" => return Ok(Parsed::Help),
            "--supports" => o.supports = Some(value()?.into()),
            "--anchor-boundary" => o.anchor_boundary = true,
            "--anchor-lowest" => o.anchor_lowest = Some(tolerance(&flag, &value()?)?),
            "--weld" => o.weld = Some(number(&flag, &value()?)?),
            "--no-weld" => o.weld = None,
            "--strict" => o.strict = true,
            "--up" => o.up = choice(&flag, &value()?)?,
            "--out" => o.out = Some(value()?.into()),
            "--report" => o.report = Some(value()?.into()),
            "--pictures" => o.pictures = Some(value()?.into()),
            "--solid" => {
                let thickness = solid_thickness(&value()?)?;
                let out = value().map_err(|_| "--solid: expected THICKNESS OUT".to_string())?;
                o.solid = Some((thickness, out.into()));
            }
            "--solid-unit-weight" => {
                let w = number(&flag, &value()?)?;
                if w <= 0.0 {
                    return Err(format!("{flag}: must be > 0, got {w}"));
                }
                o.solid_unit_weight = Some(w);
            }
            "--ascii" => o.ascii = true,
            "--stress-only" => o.stress_only = true,
            "--method" => s.method = choice(&flag, &value()?)?,
            "--fairness" => s.fairness = number(&flag, &value()?)?,
            "--max-height-change" => s.max_height_change = number(&flag, &value()?)?,
            "--solver" => s.stress.formulation = choice(&flag, &value()?)?,
            "--qp" => s.stress.solver = choice(&flag, &value()?)?,
            "--tol" => s.tolerance = number(&flag, &value()?)?,
            "--max-iter" => {
                let text = value()?;
                s.max_iterations = text
                    .parse::<usize>()
                    .map_err(|_| format!("{flag}: expected an integer >= 1, got `{text}`"))?;
            }
            "--qmin" => s.stress.q_min = bound(&flag, &value()?)?,
            "--qmin-scope" => s.stress.q_min_scope = choice(&flag, &value()?)?,
            "--qmax" => {
                let text = value()?;
                s.stress.q_max = match text.as_str() {
                    "none" => None,
                    _ => Some(bound(&flag, &text)?),
                };
            }
            "--tau" => {
                s.stress.tau = choice(&flag, &value()?)?;
                if s.stress.tau == TauMode::Prescribed {
                    return Err(format!(
                        "{flag}: prescribed needs a value per vertex, which the command line \
                         cannot give: use optimized or zero"
                    ));
                }
            }
            "--holes" => s.stress.holes = choice(&flag, &value()?)?,
            "--dual-smoothing" => s.stress.dual_length_smoothing = number(&flag, &value()?)?,
            "--smoothing-decay" => s.smoothing_decay = number(&flag, &value()?)?,
            "--odt" => {
                let text = value()?;
                o.odt = match text.parse::<usize>() {
                    Ok(n) => Some(n),
                    _ => return Err(format!("{flag}: expected an integer >= 0, got `{text}`")),
                };
                s.odt_iterations = o.odt.unwrap_or(0);
            }
            "--density" => {
                let d = number(&flag, &value()?)?;
                if d <= 0.0 {
                    return Err(format!("{flag}: must be > 0, got {d}"));
                }
                o.density = d;
            }
            "--load" => s.stress.load_rule = choice(&flag, &value()?)?,
            _ => {
                if !crate::assess::args::flag(&flag, &mut value, &mut o.assess)? {
                    return Err(format!("unknown option `{flag}`; try --help"));
                }
            }
        }
    }
    check(&o)?;
    Ok(Parsed::Run(Box::new(o)))
}

/// `--solid` and `--solid-unit-weight` together or not at all.
fn check_solid(o: &Options) -> Result<(), String> {
    match (&o.solid, o.solid_unit_weight) {
        (Some((SolidThickness::FromDensity, _)), None) => {
            return Err("--solid density needs --solid-unit-weight W".into())
        }
        (Some((SolidThickness::Uniform(_), _)), Some(_)) => {
            return Err(
                "--solid-unit-weight goes with --solid density, not with a thickness".into(),
            )
        }
        (None, Some(_)) => return Err("--solid-unit-weight needs --solid density OUT".into()),
        _ => {}
    }
    if let Some((_, out)) = &o.solid {
        voussoir::io::MeshFormat::from_path(out).map_err(|e| format!("--solid: {e}"))?;
    }
    Ok(())
}

/// Combinations of options that cannot work.
fn check(o: &Options) -> Result<(), String> {
    let ways = [
        o.supports.is_some(),
        o.anchor_boundary,
        o.anchor_lowest.is_some(),
    ];
    match (&o.mesh, ways.iter().filter(|w| **w).count()) {
        (None, 0) => {}
        (None, _) => {
            return Err("--supports, --anchor-boundary and --anchor-lowest need a MESH".into())
        }
        (Some(_), 0) => {
            return Err(
                "MESH needs --supports S.json, --anchor-boundary or --anchor-lowest TOL".into(),
            )
        }
        (Some(_), 1) => {}
        (Some(_), _) => {
            return Err(
                "give one of --supports, --anchor-boundary and --anchor-lowest, not several".into(),
            )
        }
    }
    if o.up != UpAxis::Z && o.mesh.is_none() {
        return Err("--up y needs a MESH (the embedded vault is Z-up)".into());
    }
    if let Some(out) = &o.out {
        let format = voussoir::io::MeshFormat::from_path(out).map_err(|e| format!("--out: {e}"))?;
        if format == voussoir::io::MeshFormat::ThreeMf {
            return Err(
                "--out: 3MF holds closed solids, not the open shell: write a solid with \
                 --solid T OUT.3mf, or the shell as .obj, .off, .ply or .stl"
                    .into(),
            );
        }
    }
    check_solid(o)?;
    crate::assess::args::check(o, &o.given)?;
    if o.mesh.is_some() {
        o.read_options().validate().map_err(flag_error)?;
    }
    o.settings.validate().map_err(flag_error)
}

/// The options that set each field the library's `validate` names.
const FLAGS: [(&str, &str); 10] = [
    ("tolerance", "--tol"),
    ("max_iterations", "--max-iter"),
    ("fairness", "--fairness"),
    ("max_height_change", "--max-height-change"),
    ("smoothing_decay", "--smoothing-decay"),
    ("q_min", "--qmin"),
    ("q_max", "--qmax"),
    ("dual_length_smoothing", "--dual-smoothing"),
    ("weld_tolerance", "--weld"),
    ("anchor_lowest", "--anchor-lowest"),
];

/// A settings error of the library, named by the option that set the field.
fn flag_error(e: voussoir::Error) -> String {
    match e {
        voussoir::Error::InvalidArgument { name, reason } => {
            let flag = FLAGS.iter().find(|(field, _)| *field == name);
            format!("{}: {reason}", flag.map_or(name, |f| f.1))
        }
        e => e.to_string(),
    }
}
