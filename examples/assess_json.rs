//! Masonry assessment from a JSON problem, the result printed as JSON: the Rust side of the
//! side-by-side benchmark against compas_tno (benches/tno/compare.py).
//!
//!     cargo run --release --example assess_json -- problem.json
//!
//! The problem: `vertices` ([x, y, z] per vertex; z is used only at fixed supports), `faces`
//! (triangles), `anchored` (vertex ids), `lower` and `upper` (heights per vertex), `loads`
//! (downward load per vertex: the loads alone, no self-weight is added), `objective` (fit,
//! min-thickness, min-thrust, max-thrust, max-load), optional `fixed_supports` (false),
//! `load_pattern` (per vertex, for max-load) and `max_iterations`, and the free supports'
//! springing joints (docs/method.md §16.1): optional `reach` (per vertex) and `springing`
//! (per vertex, default `lower`). Without `reach` the supports have no joint, their heights
//! bounded by `lower` and `upper` alone: compas_tno's default constraints (`funicular`,
//! `envelope`, without `reac_bounds`).

use serde_json::{json, Value};
use voussoir::{assess, AssessSettings, Envelope, Mesh, Objective, Problem, Thickness};

fn field<'a>(doc: &'a Value, name: &str) -> Result<&'a Value, String> {
    doc.get(name)
        .ok_or_else(|| format!("the problem has no '{name}'"))
}

fn numbers(doc: &Value, name: &str) -> Result<Vec<f64>, String> {
    let list = field(doc, name)?
        .as_array()
        .ok_or_else(|| format!("'{name}' is not an array"))?;
    list.iter()
        .enumerate()
        .map(|(i, x)| {
            x.as_f64()
                .ok_or_else(|| format!("'{name}'[{i}] is not a number"))
        })
        .collect()
}

fn rows<const N: usize, T>(
    doc: &Value,
    name: &str,
    read: impl Fn(&Value) -> Option<T>,
) -> Result<Vec<[T; N]>, String>
where
    T: Copy + Default,
{
    let list = field(doc, name)?
        .as_array()
        .ok_or_else(|| format!("'{name}' is not an array"))?;
    list.iter()
        .enumerate()
        .map(|(i, row)| {
            let items = row.as_array().filter(|r| r.len() == N);
            let items = items.ok_or_else(|| format!("'{name}'[{i}] is not {N} values"))?;
            let mut out = [T::default(); N];
            for (k, x) in items.iter().enumerate() {
                out[k] = read(x).ok_or_else(|| format!("'{name}'[{i}][{k}] is not valid"))?;
            }
            Ok(out)
        })
        .collect()
}

fn run(doc: &Value) -> Result<Value, String> {
    let vertices = rows::<3, f64>(doc, "vertices", Value::as_f64)?;
    let faces = rows::<3, u32>(doc, "faces", |x| x.as_u64().map(|v| v as u32))?;
    let anchored: Vec<u32> = numbers(doc, "anchored")?
        .iter()
        .map(|&a| a as u32)
        .collect();
    let objective: Objective = field(doc, "objective")?
        .as_str()
        .ok_or("'objective' is not a string")?
        .parse()
        .map_err(|e| format!("{e}"))?;
    let fixed = doc.get("fixed_supports").and_then(Value::as_bool);
    let mut settings = AssessSettings::default()
        .with_unit_weight(0.0)
        .with_objective(objective)
        .with_fixed_supports(fixed.unwrap_or(false));
    if doc.get("load_pattern").is_some() {
        settings = settings.with_load_pattern(numbers(doc, "load_pattern")?);
    }
    if let Some(n) = doc.get("max_iterations").and_then(Value::as_u64) {
        settings = settings.with_max_iterations(n as usize);
    }
    let mesh = Mesh::new(vertices, faces, &anchored).map_err(|e| format!("{e}"))?;
    let lower = numbers(doc, "lower")?;
    let upper = numbers(doc, "upper")?;
    let envelope = Envelope::from_bounds(&mesh, lower.clone(), upper, &Thickness::Uniform(1.0))
        .map_err(|e| format!("{e}"))?;
    let reach = match doc.get("reach") {
        Some(_) => numbers(doc, "reach")?,
        None => vec![f64::INFINITY; lower.len()],
    };
    let springing = match doc.get("springing") {
        Some(_) => numbers(doc, "springing")?,
        None => lower,
    };
    let envelope = (envelope.with_springing(springing, reach)).map_err(|e| format!("{e}"))?;
    let problem = Problem::new(mesh)
        .with_extra_loads(numbers(doc, "loads")?)
        .map_err(|e| format!("{e}"))?;
    let r = assess(&problem, &envelope, &settings, None).map_err(|e| format!("{e}"))?;
    Ok(json!({
        "objective": r.objective.as_str(),
        "feasible": r.feasible,
        "termination": format!("{:?}", r.termination),
        "iterations": r.iterations,
        "seconds": r.seconds,
        "thrust_horizontal": r.thrust_horizontal,
        "load_factor": r.load_factor,
        "unbounded": r.unbounded,
        "thickness_scale": r.thickness_scale,
        "eps_inf": r.eps_inf,
        "worst_bound": r.worst_bound.0,
        "z": r.positions.iter().map(|p| p[2]).collect::<Vec<_>>(),
        "force_densities": r.force_densities,
    }))
}

fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| {
        eprintln!("usage: assess_json PROBLEM.json");
        std::process::exit(2)
    });
    let outcome = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read {path}: {e}"))
        .and_then(|text| serde_json::from_str(&text).map_err(|e| format!("{path}: {e}")))
        .and_then(|doc| run(&doc));
    match outcome {
        Ok(result) => println!("{result}"),
        Err(message) => {
            eprintln!("assess_json: {message}");
            std::process::exit(1)
        }
    }
}
