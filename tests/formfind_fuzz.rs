//! The `formfind` example on mutated shared models: every mutation makes the input invalid
//! (a malformed or unknown line, a bad index, a reversed, repeated or stacked face, a NaN or
//! unrepresentable coordinate, bad supports), and every run must end with exit status 2, one
//! line on stderr and no file written.
//!
//! `VSR_FUZZ_CASES` sets the number of runs (24 by default, as in CI; a few thousand locally),
//! `VSR_FUZZ_SEED` the seed of the first (each run's seed is printed with its failure).

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

fn run_case(models: &Path, names: &[String], seed: u64) {
    let mut rng = Rng::new(seed);
    let name = rng.pick(names).clone();
    let mut model = Model {
        lines: fs::read_to_string(models.join(format!("{name}.obj")))
            .unwrap()
            .lines()
            .map(String::from)
            .collect(),
        supports: fs::read_to_string(models.join(format!("{name}.json"))).unwrap(),
    };
    let which = rng.below(MUTATIONS.len());
    mutate(&mut model, which, &mut rng);
    let dir = Scratch::new(&format!("fuzz-{seed}"));
    fs::write(dir.path("m.obj"), model.lines.join("\n") + "\n").unwrap();
    fs::write(dir.path("s.json"), &model.supports).unwrap();
    let before = dir.snapshot();
    let args = [
        "m.obj",
        "--supports",
        "s.json",
        "--out",
        "outs/o.obj",
        "--report",
        "outs/r.json",
        "--pictures",
        "outs/pics",
    ];
    let out = run(&dir.0, &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let case = format!("seed {seed}: {name}, {}", MUTATIONS[which]);
    assert_eq!(out.status.code(), Some(2), "{case}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{case}: not one line: {stderr}");
    assert!(
        dir.snapshot() == before,
        "{case}: files written: {:?}",
        dir.listing()
    );
}

#[test]
fn mutated_shared_models_get_exit_2_one_line_and_no_file() {
    let Some(models) = models_dir() else { return };
    let mut names: Vec<String> = fs::read_dir(&models)
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
    let cases = env_number("VSR_FUZZ_CASES", 24);
    let first = env_number("VSR_FUZZ_SEED", 1);
    for seed in first..first + cases {
        run_case(&models, &names, seed);
    }
    println!("{cases} mutated models from seed {first}: exit 2, one line, no file");
}
