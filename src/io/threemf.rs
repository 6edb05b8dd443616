//! 3MF (3D Manufacturing Format), written only: a zip package (through the `zip` crate) of
//! three XML parts, the content types, the package relationship and one model with one mesh
//! object. 3MF holds closed solids, so the mesh must be closed.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::{Cursor, Write as _};
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::{CompressionMethod, ZipWriter};

use super::atomic::write_atomically;
use crate::{Error, Result};

const CONTENT_TYPES: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">
  <Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>
  <Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>
</Types>
"#;

const RELATIONSHIPS: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">
  <Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>
</Relationships>
"#;

/// The path of the model part inside the package.
pub(crate) const MODEL_PART: &str = "3D/3dmodel.model";

/// Writes a closed triangle mesh as a 3MF package: one object of type `model`, in
/// millimetres (3MF's default unit; the positions are written as they are), coordinates as
/// the shortest decimals that read back to the same `f64`. A mesh with an edge not shared by
/// exactly two faces in opposite directions is an [`Error::InvalidArgument`] naming it.
pub(crate) fn write_3mf(path: &Path, positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Result<()> {
    check_closed(faces)?;
    let model = model_xml(positions, faces);
    let package = package(&model).map_err(|e| Error::Io {
        path: path.display().to_string(),
        reason: super::one_line(&e),
    })?;
    write_atomically(path, |out| out.write_all(&package))
}

fn model_xml(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> String {
    let mut xml = String::with_capacity(64 * (positions.len() + faces.len()) + 512);
    xml.push_str(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" \
         xml:lang=\"en-US\" xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n\
         <resources>\n<object id=\"1\" type=\"model\">\n<mesh>\n<vertices>\n",
    );
    for [x, y, z] in positions {
        // Writing to a String cannot fail.
        let _ = writeln!(xml, "<vertex x=\"{x:?}\" y=\"{y:?}\" z=\"{z:?}\"/>");
    }
    xml.push_str("</vertices>\n<triangles>\n");
    for [a, b, c] in faces {
        let _ = writeln!(xml, "<triangle v1=\"{a}\" v2=\"{b}\" v3=\"{c}\"/>");
    }
    xml.push_str(
        "</triangles>\n</mesh>\n</object>\n</resources>\n<build>\n<item objectid=\"1\"/>\n\
         </build>\n</model>\n",
    );
    xml
}

fn package(model: &str) -> zip::result::ZipResult<Vec<u8>> {
    let mut zip = ZipWriter::new(Cursor::new(Vec::new()));
    let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    for (name, text) in [
        ("[Content_Types].xml", CONTENT_TYPES),
        ("_rels/.rels", RELATIONSHIPS),
        (MODEL_PART, model),
    ] {
        zip.start_file(name, options)?;
        zip.write_all(text.as_bytes())?;
    }
    Ok(zip.finish()?.into_inner())
}

/// Every directed edge must appear once, and its reverse once.
fn check_closed(faces: &[[u32; 3]]) -> Result<()> {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * faces.len());
    for f in faces {
        for k in 0..3 {
            *directed.entry((f[k], f[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut bad: Vec<(u32, u32)> = directed
        .iter()
        .filter(|(&(a, b), &n)| n != 1 || directed.get(&(b, a)) != Some(&1))
        .map(|(&e, _)| e)
        .collect();
    bad.sort_unstable();
    match bad.first() {
        Some((a, b)) => Err(Error::InvalidArgument {
            name: "faces",
            reason: format!(
                "3MF holds closed solids, but the edge from vertex {a} to vertex {b} is not \
                 shared by exactly two faces in opposite directions"
            ),
        }),
        None if faces.is_empty() => Err(Error::InvalidArgument {
            name: "faces",
            reason: "3MF holds closed solids, and there are no faces".to_string(),
        }),
        None => Ok(()),
    }
}
