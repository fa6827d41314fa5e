//! The per-file pipeline: read a document, replace each triangle primitive by its smooth
//! tessellation, write it back. [`process_document`] is the seam where the surface code plugs in.
//!
//! It deliberately knows nothing of the command line, of batches or of watching files.

use std::path::Path;

use crate::gltf_io::{self, Document, WriteOptions};
use crate::options::Options;

/// What processing one document did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Report {
    /// Triangle primitives replaced.
    pub primitives: usize,
    /// Triangles read.
    pub triangles_in: usize,
    /// Triangles written.
    pub triangles_out: usize,
}

/// Replaces every triangle primitive of `doc` according to `options`.
///
/// Today this is the identity tessellation (level 1, h = 0) whatever the options say: each
/// primitive is decoded and written back as a triangle list with the same vertices and
/// triangles. The surface pipeline replaces the body of the loop.
pub fn process_document(doc: &mut Document, options: &Options) -> Result<Report, gltf_io::Error> {
    let mut report = Report::default();
    for (mesh, prim) in doc.triangle_primitives() {
        let data = doc.read_primitive(mesh, prim)?;
        report.triangles_in += data.indices.len() / 3;
        let out = data; // seam: tessellate here
        report.triangles_out += out.indices.len() / 3;
        if report.triangles_out as u64 > options.max_output_triangles {
            return Err(gltf_io::Error::invalid(
                format!("meshes[{mesh}].primitives[{prim}]"),
                format!(
                    "output would exceed {} triangles (expected at most max_output_triangles; lower --level)",
                    options.max_output_triangles
                ),
            ));
        }
        gltf_io::replace_primitive(doc, mesh, prim, &out)?;
        report.primitives += 1;
    }
    Ok(report)
}

/// Reads `input`, processes it and writes `output`.
pub fn process_file(
    input: &Path,
    output: &Path,
    options: &Options,
) -> Result<Report, gltf_io::Error> {
    let mut doc = gltf_io::read(input, &options.read_options())?;
    let report = process_document(&mut doc, options)?;
    let write = WriteOptions::new(Some(input.to_path_buf()), options.force);
    gltf_io::write(&doc, output, &write)?;
    Ok(report)
}
