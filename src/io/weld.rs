//! Welding: vertices that coincide (within a tolerance) merged into one, as STL files and many
//! exporters duplicate every vertex along seams.

use std::collections::HashMap;

use crate::{Error, Result};

/// Default welding tolerance, relative to the diagonal of the bounding box.
pub const DEFAULT_WELD_TOLERANCE: f64 = 1e-9;

/// A welded mesh and how its vertices relate to the input's.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Welded {
    /// One position per welded vertex: that of its first input vertex, unchanged. Welded
    /// vertices are numbered in the order of their first input vertex.
    pub positions: Vec<[f64; 3]>,
    /// The faces on welded ids, in input order, less those that collapsed.
    pub faces: Vec<[u32; 3]>,
    /// The welded id of each input vertex.
    pub welded_id: Vec<u32>,
    /// How many input vertices were merged into an earlier one (input minus welded count).
    pub merged: usize,
    /// Input faces dropped because welding merged two of their corners.
    pub collapsed_faces: Vec<usize>,
    /// The absolute tolerance used: the relative one times the bounding box diagonal.
    pub tolerance: f64,
}

impl Welded {
    /// The welded ids of input vertex ids (such as supports), each once, in input order. An
    /// id `>=` the input vertex count, or listed twice, is an [`Error::InvalidAnchor`].
    pub fn map_ids(&self, ids: &[u32]) -> Result<Vec<u32>> {
        let mut seen = vec![false; self.positions.len()];
        let mut listed = vec![false; self.welded_id.len()];
        let mut out = Vec::with_capacity(ids.len());
        for &id in ids {
            // The same input id twice is a mistake; two ids of one seam are not.
            if listed.get(id as usize).copied() == Some(true) {
                return Err(Error::InvalidAnchor {
                    index: u64::from(id),
                    reason: "listed twice",
                });
            }
            if let Some(flag) = listed.get_mut(id as usize) {
                *flag = true;
            }
            let welded = *self
                .welded_id
                .get(id as usize)
                .ok_or(Error::InvalidAnchor {
                    index: u64::from(id),
                    reason: "out of range",
                })?;
            if !std::mem::replace(&mut seen[welded as usize], true) {
                out.push(welded);
            }
        }
        Ok(out)
    }
}

/// Merges every vertex that lies within `relative_tolerance` × (bounding box diagonal) of an
/// earlier kept vertex into it (0 merges exactly equal positions only). A vertex joins the
/// first kept vertex within reach, so the result does not depend on chains of near vertices
/// beyond the tolerance. Faces whose corners merge are dropped and listed.
///
/// Errors: a negative or non-finite tolerance, a non-finite coordinate, a face index out of
/// range, faces that all collapse (nothing would be left) ([`Error::InvalidArgument`]).
pub fn weld(positions: &[[f64; 3]], faces: &[[u32; 3]], relative_tolerance: f64) -> Result<Welded> {
    if !(relative_tolerance.is_finite() && relative_tolerance >= 0.0) {
        return Err(Error::InvalidArgument {
            name: "weld_tolerance",
            reason: format!("{relative_tolerance} is not a finite number >= 0"),
        });
    }
    super::atomic::check_positions_finite(positions)?;
    super::atomic::check_face_indices(positions.len(), faces)?;
    // Coordinates whose diagonal overflows are left to mesh validation, which names them.
    let tolerance = relative_tolerance * diagonal(positions);
    let welded_id = if tolerance > 0.0 && tolerance.is_finite() {
        weld_within(positions, tolerance)
    } else {
        weld_exact(positions)
    };
    let n_welded = welded_id.iter().map(|&w| w as usize + 1).max().unwrap_or(0);
    let mut new_positions = vec![[0.0; 3]; n_welded];
    for (v, &w) in welded_id.iter().enumerate().rev() {
        new_positions[w as usize] = positions[v];
    }
    let mut new_faces = Vec::with_capacity(faces.len());
    let mut collapsed_faces = Vec::new();
    for (t, f) in faces.iter().enumerate() {
        let [a, b, c] = f.map(|i| welded_id[i as usize]);
        if a == b || b == c || a == c {
            collapsed_faces.push(t);
        } else {
            new_faces.push([a, b, c]);
        }
    }
    if new_faces.is_empty() && !faces.is_empty() {
        return Err(Error::InvalidArgument {
            name: "weld_tolerance",
            reason: format!(
                "welding within {tolerance:.4e} ({relative_tolerance:e} x the bounding-box \
                 diagonal) merges two corners of every face ({} in all), so no face is left: \
                 give a smaller weld tolerance",
                faces.len()
            ),
        });
    }
    Ok(Welded {
        merged: positions.len() - n_welded,
        positions: new_positions,
        faces: new_faces,
        welded_id,
        collapsed_faces,
        tolerance,
    })
}

fn diagonal(positions: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if positions.is_empty() {
        return 0.0;
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// Exactly equal positions (with `-0.0 == 0.0`).
fn weld_exact(positions: &[[f64; 3]]) -> Vec<u32> {
    let mut first: HashMap<[u64; 3], u32> = HashMap::new();
    positions
        .iter()
        .map(|p| {
            let key = p.map(|c| (c + 0.0).to_bits());
            let next = first.len() as u32;
            *first.entry(key).or_insert(next)
        })
        .collect()
}

/// Positions within `tolerance` of an earlier kept one, found through a grid of that cell size.
fn weld_within(positions: &[[f64; 3]], tolerance: f64) -> Vec<u32> {
    let cell = |p: &[f64; 3]| p.map(|c| (c / tolerance).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut kept: Vec<usize> = Vec::new();
    let mut welded_id = Vec::with_capacity(positions.len());
    for (v, p) in positions.iter().enumerate() {
        let c = cell(p);
        let near = neighbours(c)
            .filter_map(|n| grid.get(&n))
            .flatten()
            .copied()
            .filter(|&w| distance(&positions[kept[w as usize]], p) <= tolerance)
            .min();
        let id = near.unwrap_or_else(|| {
            let id = kept.len() as u32;
            kept.push(v);
            grid.entry(c).or_default().push(id);
            id
        });
        welded_id.push(id);
    }
    welded_id
}

fn neighbours(c: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (0..27).map(move |k| {
        let d = [k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1];
        [
            c[0].saturating_add(d[0]),
            c[1].saturating_add(d[1]),
            c[2].saturating_add(d[2]),
        ]
    })
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}
