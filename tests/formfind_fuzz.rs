//! The `formfind` example on mutated shared models: every mutation makes the input invalid
//! (a malformed or unknown line, a bad index, a reversed, repeated or stacked face, a NaN or
//! unrepresentable coordinate, bad supports), and every run must end with exit status 2, one
//! line on stderr and no file written. The same holds for the models written as PLY (ASCII and
//! binary), OFF and STL (ASCII and binary) with their header counts and face lines set to
//! values at the limits of their types (0, -1, one off, 2^31, 2^32, 2^63, 2^64 and beyond), and
//! for outputs that are devices, FIFOs, links to those or to the inputs, or the inputs.
//!
//! `VSR_FUZZ_CASES` sets the number of runs of each kind (24 by default, as in CI; a few
//! thousand locally), `VSR_FUZZ_SEED` the seed of the first (each run's seed is printed with
//! its failure).

#[path = "formfind_fuzz/formats.rs"]
mod formats;
mod formfind_support;

use std::fs;
use std::path::Path;

use formfind_support::*;

/// xorshift64*: small, seedable, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }

    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// A model as text: its OBJ lines and its supports file.
struct Model {
    lines: Vec<String>,
    supports: String,
}

impl Model {
    fn indices_of(&self, keyword: &str) -> Vec<usize> {
        (0..self.lines.len())
            .filter(|&i| self.lines[i].split_whitespace().next() == Some(keyword))
            .collect()
    }

    fn n_vertices(&self) -> usize {
        self.indices_of("v").len()
    }

    /// Replaces token `k` (0 is the keyword) of line `i`; `None` removes it.
    fn set_token(&mut self, i: usize, k: usize, value: Option<String>) {
        let mut tokens: Vec<String> = self.lines[i].split_whitespace().map(String::from).collect();
        match value {
            Some(v) => tokens[k] = v,
            None => drop(tokens.remove(k)),
        }
        self.lines[i] = tokens.join(" ");
    }

    /// The 1-based vertex ids of face line `i`.
    fn face(&self, i: usize) -> Vec<usize> {
        let tokens = self.lines[i].split_whitespace().skip(1);
        tokens.map(|t| t.parse().unwrap()).collect()
    }
}

const MUTATIONS: [&str; 12] = [
    "garbage coordinate",
    "vertex without its z",
    "face index out of range",
    "face index 0",
    "face with two vertices",
    "unknown statement",
    "repeated face",
    "reversed face",
    "NaN coordinate",
    "stacked copy",
    "coordinates of 1e200",
    "bad supports",
];

/// Applies mutation `which` to `m`; every one of them makes the model invalid.
fn mutate(m: &mut Model, which: usize, rng: &mut Rng) {
    let (verts, faces) = (m.indices_of("v"), m.indices_of("f"));
    let n = m.n_vertices();
    let (v, f) = (*rng.pick(&verts), *rng.pick(&faces));
    match MUTATIONS[which] {
        "garbage coordinate" => {
            let junk = ["x", "1..2", "--1", "1e", "0x10", "1,5", "½"];
            let text = rng.pick(&junk).to_string();
            m.set_token(v, 1 + rng.below(3), Some(text));
        }
        "vertex without its z" => m.set_token(v, 3, None),
        "face index out of range" => {
            let index = n + 1 + rng.below(1000);
            m.set_token(f, 1 + rng.below(3), Some(index.to_string()));
        }
        "face index 0" => m.set_token(f, 1 + rng.below(3), Some("0".into())),
        "face with two vertices" => m.set_token(f, 1 + rng.below(3), None),
        "unknown statement" => {
            let lines = [
                "F 1 2 3",
                "f, 1 2 3",
                "\u{200b}f 1 2 3",
                "vertex 0 0 0",
                "face 1 2 3",
            ];
            let at = rng.below(m.lines.len() + 1);
            m.lines.insert(at, rng.pick(&lines).to_string());
        }
        "repeated face" => m.lines.push(m.lines[f].clone()),
        "reversed face" => {
            let ids = m.face(f);
            m.lines[f] = format!("f {} {} {}", ids[0], ids[2], ids[1]);
        }
        "NaN coordinate" => {
            let vertex = m.face(f)[rng.below(3)];
            m.set_token(verts[vertex - 1], 1 + rng.below(3), Some("nan".into()));
        }
        "stacked copy" => {
            // The model again, shifted by a fifth of its width: its faces overlap the model's.
            let xs: Vec<f64> = verts
                .iter()
                .map(|&i| {
                    m.lines[i]
                        .split_whitespace()
                        .nth(1)
                        .unwrap()
                        .parse()
                        .unwrap()
                })
                .collect();
            let width = xs.iter().cloned().fold(f64::MIN, f64::max)
                - xs.iter().cloned().fold(f64::MAX, f64::min);
            let copies: Vec<String> = (verts.iter().zip(&xs))
                .map(|(&i, x)| {
                    let t: Vec<&str> = m.lines[i].split_whitespace().collect();
                    format!("v {} {} {}", x + 0.2 * width, t[2], t[3])
                })
                .chain(faces.iter().map(|&i| {
                    let ids = m.face(i);
                    format!("f {} {} {}", ids[0] + n, ids[1] + n, ids[2] + n)
                }))
                .collect();
            m.lines.extend(copies);
        }
        "coordinates of 1e200" => {
            for &i in &verts {
                let t: Vec<f64> = (m.lines[i].split_whitespace().skip(1))
                    .map(|c| c.parse::<f64>().unwrap() * 1e200)
                    .collect();
                m.lines[i] = format!("v {:e} {:e} {:e}", t[0], t[1], t[2]);
            }
        }
        "bad supports" => {
            let ids: serde_json::Value = serde_json::from_str(&m.supports).unwrap();
            let ids: Vec<u64> = serde_json::from_value(ids["anchored"].clone()).unwrap();
            m.supports = match rng.below(5) {
                0 => format!("[{}, {}]", ids[0], n + rng.below(100)),
                1 => format!("[{}, {}]", ids[0], ids[0]),
                2 => format!("[{}, -1]", ids[0]),
                3 => m.supports[..m.supports.len() / 2].to_string(),
                _ => "[]".to_string(),
            };
        }
        other => unreachable!("{other}"),
    }
}

fn env_number(name: &str, default: u64) -> u64 {
    match std::env::var(name) {
        Ok(text) => text
            .parse()
            .unwrap_or_else(|_| panic!("{name}: expected a number, got `{text}`")),
        Err(_) => default,
    }
}

fn load(models: &Path, name: &str) -> Model {
    Model {
        lines: fs::read_to_string(models.join(format!("{name}.obj")))
            .unwrap()
            .lines()
            .map(String::from)
            .collect(),
        supports: fs::read_to_string(models.join(format!("{name}.json"))).unwrap(),
    }
}

/// Runs formfind on `input` (a file name in `dir`) with `extra` arguments; asserts exit status
/// 2, one line on stderr and no file written or changed.
fn assert_refused(dir: &Scratch, args: &[&str], case: &str) {
    let before = dir.snapshot();
    let out = run(&dir.0, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{case}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{case}: not one line: {stderr}");
    assert!(
        stderr.len() < 1000,
        "{case}: {} bytes on stderr",
        stderr.len()
    );
    assert!(
        dir.snapshot() == before,
        "{case}: files written: {:?}",
        dir.listing()
    );
}

fn run_case(models: &Path, names: &[String], seed: u64) {
    let mut rng = Rng::new(seed);
    let name = rng.pick(names).clone();
    let mut model = load(models, &name);
    let which = rng.below(MUTATIONS.len());
    mutate(&mut model, which, &mut rng);
    let dir = Scratch::new(&format!("fuzz-{seed}"));
    fs::write(dir.path("m.obj"), model.lines.join("\n") + "\n").unwrap();
    fs::write(dir.path("s.json"), &model.supports).unwrap();
    let args = ["m.obj", "--supports", "s.json", "--out", "outs/o.obj"];
    let case = format!("seed {seed}: {name}, {}", MUTATIONS[which]);
    assert_refused(&dir, &[&args[..], &OUTS[..]].concat(), &case);
}

/// The report's and pictures' paths of every run, inside a folder the run would create.
const OUTS: [&str; 4] = ["--report", "outs/r.json", "--pictures", "outs/pics"];

fn model_names(models: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(models)
        .unwrap()
        .filter_map(|e| {
            let path = e.unwrap().path();
            let stem = path.file_stem()?.to_str()?.to_string();
            let paired =
                path.extension()? == "obj" && models.join(format!("{stem}.json")).is_file();
            paired.then_some(stem)
        })
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no model in {}", models.display());
    names
}

#[test]
fn counts_and_face_lines_at_their_limits_in_every_format_get_exit_2() {
    let Some(models) = models_dir() else { return };
    let names = model_names(&models);
    let cases = env_number("VSR_FUZZ_CASES", 24);
    let first = env_number("VSR_FUZZ_SEED", 1);
    for seed in first..first + cases {
        let mut rng = Rng::new(seed ^ 0x5eed_f0f0);
        let name = rng.pick(&names).clone();
        let model = load(&models, &name);
        let (file, bytes, what) = formats::mutated(&model, &mut rng);
        let dir = Scratch::new(&format!("fuzz-format-{seed}"));
        fs::write(dir.path(&file), bytes).unwrap();
        let case = format!("seed {seed}: {name} as {file}, {what}");
        let args = [&file, "--anchor-boundary", "--out", "outs/o.obj"];
        assert_refused(&dir, &[&args[..], &OUTS[..]].concat(), &case);
    }
    println!("{cases} models with counts or face lines at their limits: exit 2, one line, no file");
}

#[cfg(unix)]
#[test]
fn outputs_that_are_devices_fifos_links_or_inputs_get_exit_2() {
    use std::os::unix::fs::symlink;
    let Some(models) = models_dir() else { return };
    let names = model_names(&models);
    let cases = env_number("VSR_FUZZ_CASES", 24);
    let first = env_number("VSR_FUZZ_SEED", 1);
    // Targets no output may replace; `link-*` are symbolic links made in each folder.
    let targets = [
        "/dev/null",
        "/dev/full",
        "/dev/zero",
        "/proc/self/fd/1",
        "/proc/self/fd/2",
        "fifo",
        "link-fifo",
        "link-null",
        "m.obj",
        "s.json",
        "link-mesh",
        "hard-mesh",
        "link-supports",
    ];
    for seed in first..first + cases {
        let mut rng = Rng::new(seed ^ 0x0075_7075);
        let name = rng.pick(&names).clone();
        let model = load(&models, &name);
        let dir = Scratch::new(&format!("fuzz-out-{seed}"));
        fs::write(dir.path("m.obj"), model.lines.join("\n") + "\n").unwrap();
        fs::write(dir.path("s.json"), &model.supports).unwrap();
        let made = std::process::Command::new("mkfifo")
            .arg(dir.path("fifo"))
            .status();
        assert!(made.unwrap().success());
        let option = *rng.pick(&["--out", "--report", "--solid"]);
        // --out and --solid need a mesh extension: their links carry one.
        let ext = if option == "--report" { "json" } else { "obj" };
        let target = *rng.pick(&targets);
        let path = match target.strip_prefix("link-") {
            Some(to) => {
                let to = match to {
                    "fifo" => "fifo".to_string(),
                    "null" => "/dev/null".to_string(),
                    "mesh" => "m.obj".to_string(),
                    _ => "s.json".to_string(),
                };
                let link = format!("link.{ext}");
                symlink(to, dir.path(&link)).unwrap();
                link
            }
            None if target == "hard-mesh" => {
                let hard = format!("hard.{ext}");
                fs::hard_link(dir.path("m.obj"), dir.path(&hard)).unwrap();
                hard
            }
            None => target.to_string(),
        };
        // --out and --solid refuse a path without a mesh extension before looking at it: the
        // report takes those.
        let option = if path.ends_with(".obj") {
            option
        } else {
            "--report"
        };
        let mut args = vec!["m.obj", "--supports", "s.json", "--stress-only"];
        args.extend(match option {
            "--solid" => vec!["--solid", "0.01", path.as_str()],
            _ => vec![option, path.as_str()],
        });
        let case = format!("seed {seed}: {name}, {option} {path} ({target})");
        assert_refused(&dir, &args, &case);
        for device in ["/dev/null", "/dev/full", "/dev/zero"] {
            assert!(
                !fs::metadata(device).unwrap().is_file(),
                "{case}: {device} replaced"
            );
        }
    }
    println!("{cases} runs with hostile output paths: exit 2, one line, nothing written");
}

#[test]
fn mutated_shared_models_get_exit_2_one_line_and_no_file() {
    let Some(models) = models_dir() else { return };
    let names = model_names(&models);
    let cases = env_number("VSR_FUZZ_CASES", 24);
    let first = env_number("VSR_FUZZ_SEED", 1);
    for seed in first..first + cases {
        run_case(&models, &names, seed);
    }
    println!("{cases} mutated models from seed {first}: exit 2, one line, no file");
}
