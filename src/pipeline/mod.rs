//! The per-file job: read a document, replace every triangle primitive by its dense smooth
//! surface, write it back. It reads as a recipe; each stage lives in its own module.
//!
//! It deliberately knows nothing of the command line, of batches or of watching files: the
//! binary calls [`process_file`] (or [`process_document`] on bytes already in memory).
//!
//! Meshes, not primitives, are the unit of work: all triangle primitives of one mesh are joined
//! into one [`crate::mesh::TriMesh`] so that the surface is watertight across primitives that
//! share vertices (a character's head and body with different materials), then split again.

mod error;
mod mesh_job;
mod morph;
mod primitive_out;
mod report;

use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;
use serde_json::Value;

use crate::gltf_io::{self, Document, PrimitiveData, WriteOptions};
use crate::options::Options;
use crate::sharpness::{AssetSharpness, Defaults, Sidecar};

pub use error::Error;
pub use mesh_job::{MeshInput, MeshOutput};
pub use report::{FileReport, MeshReport, PrimitiveReport, StageTimes};

/// Reads `input`, processes it and writes `output` atomically.
pub fn process_file(input: &Path, output: &Path, options: &Options) -> Result<FileReport, Error> {
    let started = Instant::now();
    let located = |e: gltf_io::Error| Error::gltf(input, e);
    let mut doc = gltf_io::read(input, &options.read_options()).map_err(located)?;
    let read_s = started.elapsed().as_secs_f64();
    let mut report = process_document(&mut doc, input, options)?;
    let write_start = Instant::now();
    if let Some(q) = options.quantization() {
        gltf_io::quantize(&mut doc, &q).map_err(located)?;
    }
    let write = WriteOptions::new(Some(input.to_path_buf()), options.force)
        .with_compression(options.compression());
    gltf_io::write(&doc, output, &write).map_err(|e| Error::gltf(output, e))?;
    report.times.read = read_s;
    report.times.write += write_start.elapsed().as_secs_f64();
    report.times.total = started.elapsed().as_secs_f64();
    report.bytes_in = file_size(input);
    report.bytes_out = file_size(output);
    Ok(report)
}

fn file_size(path: &Path) -> u64 {
    std::fs::metadata(path).map_or(0, |m| m.len())
}

/// Replaces every triangle primitive of `doc` (read from `asset`, which names it in messages
/// and locates its sidecar) by its tessellated surface.
pub fn process_document(
    doc: &mut Document,
    asset: &Path,
    options: &Options,
) -> Result<FileReport, Error> {
    let sidecar = Sidecar::discover(asset, options.sidecar.as_deref())?;
    let mesh_names: Vec<Option<&str>> = doc.root.meshes.iter().map(|m| m.name.as_deref()).collect();
    let defaults = Defaults {
        h: options.h,
        crease_angle: options.crease_angle,
        keep_hard_edges: options.keep_hard_edges,
    };
    let sharpness = AssetSharpness::new(asset, sidecar, &mesh_names, defaults)?;
    let level = sharpness.level().unwrap_or(options.level);

    // Decode every triangle primitive first (the document is only read here).
    let decode_start = Instant::now();
    let mut inputs: Vec<MeshInput> = Vec::new();
    for (mesh, prim) in doc.triangle_primitives() {
        let data = doc
            .read_primitive(mesh, prim)
            .map_err(|e| Error::gltf(asset, e))?;
        if inputs.last().map(|m| m.mesh) != Some(mesh) {
            inputs.push(MeshInput {
                mesh,
                name: doc.root.meshes[mesh].name.clone(),
                extras: raw_extras(doc, &["meshes"], mesh),
                primitives: Vec::new(),
            });
        }
        let current = inputs.last_mut().expect("pushed above");
        current.primitives.push(mesh_job::PrimitiveInput {
            index: prim,
            extras: doc
                .raw
                .pointer(&format!("/meshes/{mesh}/primitives/{prim}/extras"))
                .cloned(),
            needs_tangents: needs_tangents(doc, mesh, prim, &data),
            data,
        });
    }
    let decode_s = decode_start.elapsed().as_secs_f64();

    check_output_size(&inputs, level, options, asset)?;

    // The meshes are independent: smooth them in parallel, collect in file order.
    let outputs: Vec<Result<MeshOutput, Error>> = inputs
        .par_iter()
        .map(|m| mesh_job::smooth_mesh(m, &sharpness, level, options, asset))
        .collect();

    let mut report = FileReport {
        level,
        ..FileReport::default()
    };
    report.times.decode = decode_s;
    let store_start = Instant::now();
    for out in outputs {
        let out = out?;
        for (prim, data) in out.primitives {
            gltf_io::replace_primitive_owned(doc, out.report.mesh, prim, data)
                .map_err(|e| Error::gltf(asset, e))?;
        }
        report.add_mesh(out.report);
    }
    // Storing the new arrays in the document's buffer is the first half of writing.
    report.times.write = store_start.elapsed().as_secs_f64();
    Ok(report)
}

/// The `extras` of `collection[index]` as plain JSON, if any.
fn raw_extras(doc: &Document, collection: &[&str], index: usize) -> Option<Value> {
    let pointer = format!("/{}/{index}/extras", collection.join("/"));
    doc.raw.pointer(&pointer).cloned()
}

/// Tangents are regenerated when the input had them, or when the primitive's material has a
/// normal texture (a renderer would otherwise derive them per pixel from screen derivatives,
/// which no longer match a bake against the low-poly mesh).
fn needs_tangents(doc: &Document, mesh: usize, prim: usize, data: &PrimitiveData) -> Option<u32> {
    let normal_texture = doc.root.meshes[mesh].primitives[prim]
        .material
        .and_then(|m| doc.root.materials.get(m.value()))
        .and_then(|m| m.normal_texture.as_ref());
    match normal_texture {
        Some(t) => Some(t.tex_coord),
        None if data.attribute("TANGENT").is_some() => Some(0),
        None => None,
    }
}

/// Refuses work whose output would not fit, before allocating any of it, and says which level
/// would.
fn check_output_size(
    inputs: &[MeshInput],
    level: u32,
    options: &Options,
    asset: &Path,
) -> Result<(), Error> {
    let tris: u64 = inputs
        .iter()
        .flat_map(|m| &m.primitives)
        .map(|p| (p.data.indices.len() / 3) as u64)
        .sum();
    let out = tris.saturating_mul(u64::from(level) * u64::from(level));
    if out <= options.max_output_triangles {
        return Ok(());
    }
    let fits = (1..level)
        .rev()
        .find(|l| tris * u64::from(*l) * u64::from(*l) <= options.max_output_triangles);
    let hint = match fits {
        Some(l) => format!("level {l} would give {} triangles", tris * u64::from(l * l)),
        None => "no level fits".to_string(),
    };
    Err(Error::limit(
        asset,
        format!(
            "level {level} would write {out} triangles from {tris}, over the limit of {} (expected --level so that triangles × level² fits, or a larger --max-output-triangles; {hint})",
            options.max_output_triangles
        ),
    ))
}
