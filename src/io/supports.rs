//! JSON supports sidecar: `{"anchored": [ids], ...}` or a bare list `[ids]`.

use std::fs;
use std::path::Path;

use serde::Deserialize;

use super::io_error;
use crate::{Error, Result};

/// The models' format; other keys (`counts`, `note`, ...) are ignored.
#[derive(Deserialize)]
struct SupportsFile {
    anchored: Vec<u32>,
}

/// Reads the 0-based anchored vertex ids of a JSON supports file (see [`parse_supports`]).
pub fn read_supports(path: &Path) -> Result<Vec<u32>> {
    let bytes = fs::read(path).map_err(|e| io_error(path, &e))?;
    let text = String::from_utf8(bytes).map_err(|_| Error::Parse {
        path: path.display().to_string(),
        line: 1,
        reason: "not UTF-8 text".to_string(),
    })?;
    parse_supports(&text, &path.display().to_string())
}

/// Parses a supports file: either an object with an `anchored` list of 0-based vertex ids
/// (other keys ignored) or a bare list of ids. Ids must be integers in `0..=u32::MAX`; their
/// range and uniqueness against a mesh are checked by [`crate::Mesh::new`].
///
/// Errors are [`Error::Parse`] with `path_label` and the line of the problem (the line of
/// the offending id for negative or fractional ids, of the closing brace for a missing
/// `anchored` key).
pub fn parse_supports(text: &str, path_label: &str) -> Result<Vec<u32>> {
    let err = |line: usize, reason: String| Error::Parse {
        path: path_label.to_string(),
        line,
        reason,
    };
    let from_serde = |e: serde_json::Error, what: &str| {
        let message = e.to_string();
        // serde_json appends " at line L column C"; the line goes in its own field.
        let message = match message.rfind(" at line ") {
            Some(at) => &message[..at],
            None => &message[..],
        };
        err(
            e.line().max(1),
            format!("{what}: {} (column {})", short_quotes(message), e.column()),
        )
    };
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| from_serde(e, "invalid JSON"))?;
    // Parse again into the typed shape: serde_json then reports the line of a bad id.
    match value {
        serde_json::Value::Object(_) => serde_json::from_str::<SupportsFile>(text)
            .map(|s| s.anchored)
            .map_err(|e| {
                from_serde(
                    e,
                    "expected \"anchored\": a list of non-negative integer vertex ids",
                )
            }),
        serde_json::Value::Array(_) => serde_json::from_str::<Vec<u32>>(text)
            .map_err(|e| from_serde(e, "expected a list of non-negative integer vertex ids")),
        other => Err(err(
            1,
            format!(
                "expected an object with an \"anchored\" list or a list of vertex ids, found {}",
                json_kind(&other)
            ),
        )),
    }
}

/// `message` with every quoted part (serde_json quotes the bad value in full, which may be
/// megabytes) cut to an excerpt.
fn short_quotes(message: &str) -> String {
    let mut out = String::new();
    for (k, part) in message.split('"').enumerate() {
        if k > 0 {
            out.push('"');
        }
        if k % 2 == 1 {
            out.push_str(&super::excerpt(part));
        } else {
            out.push_str(part);
        }
    }
    out
}

fn json_kind(value: &serde_json::Value) -> &'static str {
    match value {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "a list",
        serde_json::Value::Object(_) => "an object",
    }
}
