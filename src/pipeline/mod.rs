//! The per-file job: read a document, replace every triangle primitive by its dense smooth
//! surface, write it back. It reads as a recipe; each stage lives in its own module.
//!
//! It deliberately knows nothing of the command line, of batches or of watching files: the
//! binary calls [`process_file`] (or [`process_document`] on bytes already in memory).
//!
//! Meshes, not primitives, are the unit of work: all triangle primitives of one mesh are joined
//! into one [`crate::mesh::TriMesh`] so that the surface is watertight across primitives that
//! share vertices (a character's head and body with different materials), then split again.

mod checks;
mod density;
mod error;
pub mod lod;
mod mesh_job;
mod morph;
mod primitive_out;
mod report;
mod warning;

use std::path::Path;
use std::time::Instant;

use rayon::prelude::*;

use crate::gltf_io::{self, Document, PrimitiveData, WriteOptions};
use crate::options::Options;
use crate::sharpness::{explain_rows, AssetSharpness, Defaults, Sidecar};

pub use density::AdaptiveFigures;
pub use error::Error;
pub use mesh_job::{MeshInput, MeshOutput};
pub use report::{EdgeFigures, FileReport, LodReport, MeshReport, PrimitiveReport, StageTimes};
pub use warning::{Warning, Warnings};

/// Reads `input`, processes it and writes `output` atomically.
///
/// Each mesh's arrays go to the temporary output files as soon as the mesh is done (in mesh
/// order, so the bytes do not depend on the thread count) and are freed; the files are renamed
/// into place together at the end. Quantized and compressed outputs, which need the whole
/// document, are assembled in memory first.
pub fn process_file(input: &Path, output: &Path, options: &Options) -> Result<FileReport, Error> {
    if !streams(options) {
        let started = Instant::now();
        let (mut report, files) = encode_file(input, output, options)?;
        // As on the streamed path: a stop that came while encoding writes nothing.
        mesh_job::stop_if_cancelled(options, input)?;
        let write_start = Instant::now();
        gltf_io::write_files_atomically(&files).map_err(|e| Error::gltf(output, e))?;
        report.times.write += write_start.elapsed().as_secs_f64();
        report.times.total = started.elapsed().as_secs_f64();
        return Ok(report);
    }
    stream_file(input, output, options, gltf_io::StreamMode::Write).map(|(report, _)| report)
}

/// `--check`: makes the output exactly as [`process_file`] would and compares it with the
/// files on disk as it is produced, writing nothing. Returns the report and the first file
/// (in the order they are written) that is missing or differs.
pub fn check_file(
    input: &Path,
    output: &Path,
    options: &Options,
) -> Result<(FileReport, Option<std::path::PathBuf>), Error> {
    if !streams(options) {
        let (report, files) = encode_file(input, output, options)?;
        let stale = files.iter().find(|f| !f.matches_disk());
        return Ok((report, stale.map(|f| f.path.clone())));
    }
    stream_file(input, output, options, gltf_io::StreamMode::Check)
        .map(|(report, done)| (report, done.stale))
}

/// Whether the output under `options` is written as it is produced (see [`process_file`]).
fn streams(options: &Options) -> bool {
    options.quantization().is_none()
        && options.compression().is_none()
        && !writes_level_files(options)
}

/// Reads `input`, processes it and writes (or compares) `output` mesh by mesh.
fn stream_file(
    input: &Path,
    output: &Path,
    options: &Options,
    mode: gltf_io::StreamMode,
) -> Result<(FileReport, gltf_io::Streamed), Error> {
    let started = Instant::now();
    let mut doc =
        gltf_io::read(input, &options.read_options()).map_err(|e| Error::gltf(input, e))?;
    let read_s = started.elapsed().as_secs_f64();
    let at_output = |e: gltf_io::Error| Error::gltf(output, e);
    let write = WriteOptions::new(Some(input.to_path_buf()), options.overwrite_input);
    let begin_start = Instant::now();
    let mut out =
        gltf_io::StreamedOutput::begin(&doc, output, &write, &doc.triangle_primitives(), mode)
            .map_err(at_output)?;
    let begin_s = begin_start.elapsed().as_secs_f64();
    let mut report = smooth_meshes(&mut doc, input, options, &mut |doc, step| match step {
        Step::Decoded => {
            out.release_input(doc);
            Ok(())
        }
        Step::Stored { last } => out.flush(doc, last).map_err(at_output),
    })?;
    // A stop that came while the last mesh was written: the temporaries go, nothing is
    // renamed into place (the in-memory path in `process_file` checks at the same point).
    mesh_job::stop_if_cancelled(options, input)?;
    let finish_start = Instant::now();
    let done = out.finish(&mut doc).map_err(at_output)?;
    report.times.read = read_s;
    report.times.write += begin_s + finish_start.elapsed().as_secs_f64();
    report.times.total = started.elapsed().as_secs_f64();
    report.bytes_in = file_size(input);
    report.bytes_out = done.files.iter().map(|(_, len)| len).sum();
    Ok((report, done))
}

/// Every file that processing `asset` under `options` reads: the asset, the buffer and image
/// files it refers to (as [`gltf_io::referenced_files`] resolves them), and its sidecar (the
/// one named by `--sidecar`, else the one beside it, listed whether or not it exists, since
/// creating it changes the result). Skipping up-to-date outputs, watching, and refusing an
/// output that would replace another asset's input all start from this list.
///
/// Never fails: an unreadable asset is listed alone, and processing it reports why.
pub fn files_read(asset: &Path, options: &Options) -> Vec<std::path::PathBuf> {
    let mut files = vec![asset.to_path_buf()];
    files.extend(gltf_io::referenced_files(asset, options.allow_outside_uris));
    files.push(match &options.sidecar {
        Some(s) => s.clone(),
        None => crate::sharpness::sidecar_path_for(asset),
    });
    files
}

/// Every file that [`process_file`] may write for `output` under `options` (the output, a
/// `.gltf`'s `.bin`, a compressed output's fallback buffer), by name, before any is written.
///
/// With `--lod-files`, each level's file is written instead of `output` itself
/// ([`lod::level_path`]).
pub fn files_written(output: &Path, options: &Options) -> Vec<std::path::PathBuf> {
    if !writes_level_files(options) {
        return gltf_io::output_files(output, options.compression());
    }
    (0..options.lod_levels().len())
        .flat_map(|k| gltf_io::output_files(&lod::level_path(output, k), options.compression()))
        .collect()
}

/// Whether a run writes one file per level of detail instead of one output.
fn writes_level_files(options: &Options) -> bool {
    options.lod_files && !options.lod_levels().is_empty()
}

/// Does everything [`process_file`] does except writing, all in memory: returns the files it
/// would write (see [`gltf_io::encode`]) with their bytes.
pub fn encode_file(
    input: &Path,
    output: &Path,
    options: &Options,
) -> Result<(FileReport, gltf_io::Files), Error> {
    let started = Instant::now();
    let located = |e: gltf_io::Error| Error::gltf(input, e);
    let mut doc = gltf_io::read(input, &options.read_options()).map_err(located)?;
    let read_s = started.elapsed().as_secs_f64();
    let (mut report, docs) = if writes_level_files(options) {
        let (report, docs) = process_document_per_level(&doc, input, options)?;
        let paths = (0..docs.len()).map(|k| lod::level_path(output, k));
        (report, docs.into_iter().zip(paths).collect())
    } else {
        let report = process_document(&mut doc, input, options)?;
        (report, vec![(doc, output.to_path_buf())])
    };
    let encode_start = Instant::now();
    let write = WriteOptions::new(Some(input.to_path_buf()), options.overwrite_input)
        .with_compression(options.compression());
    let mut files = gltf_io::Files::new();
    for (mut doc, path) in docs {
        if let Some(q) = options.quantization() {
            gltf_io::quantize(&mut doc, &q).map_err(located)?;
        }
        files.extend(gltf_io::encode(&doc, &path, &write).map_err(|e| Error::gltf(&path, e))?);
    }
    report.times.read = read_s;
    report.times.write += encode_start.elapsed().as_secs_f64();
    report.times.total = started.elapsed().as_secs_f64();
    report.bytes_in = file_size(input);
    report.bytes_out = files.iter().map(gltf_io::OutputFile::len).sum();
    Ok((report, files))
}

/// Runs `job` on `input` with a panic (a bug: input never panics by design) caught and turned
/// into [`Error::Internal`] naming the file, so that batch and watch mode report it and go on
/// with the other files.
///
/// The panic's own message still goes to the panic hook (stderr by default).
pub fn guarded<T>(input: &Path, job: impl FnOnce() -> Result<T, Error>) -> Result<T, Error> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(job))
        .unwrap_or_else(|payload| Err(Error::internal(input, &*payload)))
}

/// [`process_file`] inside [`guarded`].
pub fn process_file_guarded(
    input: &Path,
    output: &Path,
    options: &Options,
) -> Result<FileReport, Error> {
    guarded(input, || process_file(input, output, options))
}

fn file_size(path: &Path) -> u64 {
    std::fs::metadata(path).map_or(0, |m| m.len())
}

/// Replaces every triangle primitive of `doc` (read from `asset`, which names it in messages
/// and locates its sidecar) by its tessellated surface. With a LOD chain the finest level
/// replaces them and the coarser ones are added as meshes on nodes linked by `MSFT_lod`
/// (see [`lod::store_with_msft_lod`]).
pub fn process_document(
    doc: &mut Document,
    asset: &Path,
    options: &Options,
) -> Result<FileReport, Error> {
    smooth_meshes(doc, asset, options, &mut |_, _| Ok(()))
}

/// A point of [`smooth_meshes`] at which a writer may act on the document.
enum Step {
    /// Every triangle primitive is decoded and none is smoothed yet: a writer that no longer
    /// needs the input's bytes frees them before the surfaces are built.
    Decoded,
    /// A mesh's new primitives are stored in the document (in file order; `last` after the
    /// last): a writer can take their arrays out at once.
    Stored { last: bool },
}

/// [`process_document`], calling `step` at each [`Step`].
fn smooth_meshes(
    doc: &mut Document,
    asset: &Path,
    options: &Options,
    step: &mut dyn FnMut(&mut Document, Step) -> Result<(), Error>,
) -> Result<FileReport, Error> {
    let (sharpness, mut report, inputs) = prepare_document(doc, asset, options)?;
    step(doc, Step::Decoded)?;
    // The meshes are independent: smooth as many in parallel as there are threads, then store
    // them in file order. Only one such window of outputs (and of decoded inputs) is held at
    // a time, so a file of many large meshes never holds all their outputs at once.
    let window = rayon::current_num_threads().max(1);
    let mut left = inputs.len();
    let mut inputs = inputs.into_iter();
    let mut file_total = FileTotal::default();
    loop {
        let batch: Vec<MeshInput> = inputs.by_ref().take(window).collect();
        if batch.is_empty() {
            break;
        }
        // Each mesh's decoded arrays are freed inside as they are used.
        let outputs: Vec<Result<MeshOutput, Error>> = batch
            .into_par_iter()
            .map(|m| smooth_one(m, &sharpness, options, asset))
            .collect();
        for out in outputs {
            let out = out?;
            file_total.add(&out, options, asset)?;
            // Storing the new arrays in the document's buffer is the first half of writing.
            let store_start = Instant::now();
            let mesh_report = lod::store_with_msft_lod(doc, out, asset)?;
            left -= 1;
            step(doc, Step::Stored { last: left == 0 })?;
            report.times.write += store_start.elapsed().as_secs_f64();
            report.add_mesh(mesh_report);
        }
    }
    Ok(report)
}

/// The output triangles of one file so far, for `--max-triangles`, which bounds a file. Uniform
/// levels are checked against it from the declared counts before anything is decoded
/// ([`check_output_size`]); per-edge counts (a tolerance, a budget, a LOD chain) are known only
/// once a mesh's surface is built, so each mesh is refused there when it alone is over, and the
/// file's meshes here, added in file order so that the error is the same on any thread count.
#[derive(Default)]
struct FileTotal {
    triangles: u64,
}

impl FileTotal {
    /// Adds every level `out` writes; an error once the file is over the limit.
    fn add(&mut self, out: &MeshOutput, options: &Options, asset: &Path) -> Result<(), Error> {
        let count = |prims: &[(usize, PrimitiveData)]| -> u64 {
            prims.iter().map(|(_, p)| p.indices.len() as u64 / 3).sum()
        };
        let levels =
            count(&out.primitives) + out.lods.iter().flatten().map(|l| count(l)).sum::<u64>();
        self.triangles = self.triangles.saturating_add(levels);
        let limit = options.max_output_triangles;
        if self.triangles > limit {
            return Err(Error::limit(
                asset,
                format!(
                    "its meshes up to mesh {} would get {} triangles, over --max-triangles {limit}, which bounds a whole file (expected a larger tolerance, a smaller --triangle-budget or a larger --max-triangles)",
                    out.report.mesh, self.triangles
                ),
            ));
        }
        Ok(())
    }
}

/// [`process_document`] for `--lod-files`: one document per level of the options' LOD chain,
/// finest first, each with every mesh at that level; the meshes are smoothed once.
pub fn process_document_per_level(
    doc: &Document,
    asset: &Path,
    options: &Options,
) -> Result<(FileReport, Vec<Document>), Error> {
    let (mut report, outputs) = smooth_document(doc, asset, options)?;
    let store_start = Instant::now();
    let mut outputs: Vec<MeshOutput> = outputs.into_iter().collect::<Result<_, _>>()?;
    let mut file_total = FileTotal::default();
    for out in &outputs {
        file_total.add(out, options, asset)?;
    }
    let mut docs = Vec::new();
    for level in 0..options.lod_levels().len().max(1) {
        let mut copy = doc.clone();
        for out in &mut outputs {
            lod::store_level(&mut copy, out, level, asset)?;
        }
        docs.push(copy);
    }
    for out in outputs {
        report.add_mesh(out.report);
    }
    report.times.write = store_start.elapsed().as_secs_f64();
    Ok((report, docs))
}

/// Smooths every mesh of `doc` (the document is only read), in parallel, results in file
/// order; each mesh under its own options (the sidecar's density keys over `options`).
fn smooth_document(
    doc: &Document,
    asset: &Path,
    options: &Options,
) -> Result<(FileReport, Vec<Result<MeshOutput, Error>>), Error> {
    let (sharpness, report, inputs) = prepare_document(doc, asset, options)?;
    // The meshes are independent: smooth them in parallel, collect in file order.
    let outputs = inputs
        .into_par_iter()
        .map(|m| smooth_one(m, &sharpness, options, asset))
        .collect();
    Ok((report, outputs))
}

/// What every mesh of `doc` shares before it is smoothed: the asset's sharpness settings (its
/// sidecar), the size check, and every triangle primitive decoded; the report started.
fn prepare_document(
    doc: &Document,
    asset: &Path,
    options: &Options,
) -> Result<(AssetSharpness, FileReport, Vec<MeshInput>), Error> {
    // Smoothing reads only the effective widths.
    let sharpness = asset_sharpness(doc, asset, options)?.effective_only();
    let level = sharpness.level().unwrap_or(options.level);

    // Refuse what would not fit before decoding or allocating any of it. Per-edge counts are
    // known only once a mesh's surface is built: that mesh is checked then, here its floor.
    let varies = options.adaptive() || !options.lod_levels().is_empty() || sharpness.sets_density();
    let floor = if varies { 1 } else { level };
    check_output_size(doc, floor, options, asset)?;

    let decode_start = Instant::now();
    let inputs = mesh_inputs(doc, asset)?;
    let mut report = FileReport {
        level,
        ..FileReport::default()
    };
    report.times.decode = decode_start.elapsed().as_secs_f64();
    Ok((sharpness, report, inputs))
}

/// One mesh smoothed under its own options (the sidecar's density keys over `options`).
fn smooth_one(
    m: MeshInput,
    sharpness: &AssetSharpness,
    options: &Options,
    asset: &Path,
) -> Result<MeshOutput, Error> {
    let mesh_options = sharpness.mesh_options(m.mesh, options);
    mesh_job::smooth_mesh(m, sharpness, mesh_options.level, &mesh_options, asset)
}

/// Every mesh with triangle primitives, decoded, in file order.
fn mesh_inputs(doc: &Document, asset: &Path) -> Result<Vec<MeshInput>, Error> {
    let mut inputs: Vec<MeshInput> = Vec::new();
    for (mesh, prim) in doc.triangle_primitives() {
        let data = doc
            .read_primitive(mesh, prim)
            .map_err(|e| Error::gltf(asset, e))?;
        if inputs.last().map(|m| m.mesh) != Some(mesh) {
            inputs.push(MeshInput {
                mesh,
                name: doc.root.meshes[mesh].name.clone(),
                extras: doc.mesh_extras(mesh),
                primitives: Vec::new(),
            });
        }
        let current = inputs.last_mut().expect("pushed above");
        current.primitives.push(mesh_job::PrimitiveInput {
            index: prim,
            extras: doc.primitive_extras(mesh, prim),
            needs_tangents: needs_tangents(doc, mesh, prim, &data),
            normal_accessor: doc
                .raw
                .pointer(&format!(
                    "/meshes/{mesh}/primitives/{prim}/attributes/NORMAL"
                ))
                .and_then(serde_json::Value::as_u64)
                .map(|a| a as usize),
            data,
        });
    }
    Ok(inputs)
}

/// The sharpness sources of an asset: its sidecar, its mesh names, the options' defaults.
fn asset_sharpness(
    doc: &Document,
    asset: &Path,
    options: &Options,
) -> Result<AssetSharpness, Error> {
    let sidecar = Sidecar::discover(asset, options.sidecar.as_deref())?;
    let mesh_names: Vec<Option<&str>> = doc.root.meshes.iter().map(|m| m.name.as_deref()).collect();
    let defaults = Defaults {
        h: options.h,
        crease_angle: options.crease_angle,
        keep_hard_edges: options.keep_hard_edges,
    };
    Ok(AssetSharpness::new(asset, sidecar, &mesh_names, defaults)?)
}

/// For `--explain-h`: one line per welded edge of mesh `which` (its name or index) saying
/// which source set its h, so a user can see why an edge is sharp.
pub fn explain_h(input: &Path, options: &Options, which: &str) -> Result<Vec<String>, Error> {
    let doc = gltf_io::read(input, &options.read_options()).map_err(|e| Error::gltf(input, e))?;
    let sharpness = asset_sharpness(&doc, input, options)?.with_sources();
    let inputs = mesh_inputs(&doc, input)?;
    // As in a sidecar section: digits name an index, anything else a name, which must be
    // unique among the meshes with triangles.
    let by_index = !which.is_empty() && which.bytes().all(|b| b.is_ascii_digit());
    let hits: Vec<&mesh_job::MeshInput> = inputs
        .iter()
        .filter(|m| {
            if by_index {
                which.parse::<usize>().is_ok_and(|i| i == m.mesh)
            } else {
                m.name.as_deref() == Some(which)
            }
        })
        .collect();
    if let [first, _, ..] = hits.as_slice() {
        let indices: Vec<String> = hits.iter().map(|m| m.mesh.to_string()).collect();
        return Err(Error::Request {
            file: input.to_path_buf(),
            what: format!(
                "--explain-h {which}: mesh name \"{which}\" is shared by meshes {}; name the mesh by index, e.g. --explain-h {}",
                indices.join(", "),
                first.mesh
            ),
        });
    }
    let found = hits.first().copied();
    let Some(mesh) = found else {
        let known: Vec<String> = inputs
            .iter()
            .map(|m| match &m.name {
                Some(n) => format!("{} \"{n}\"", m.mesh),
                None => m.mesh.to_string(),
            })
            .collect();
        return Err(Error::Request {
            file: input.to_path_buf(),
            what: format!(
                "--explain-h {which}: no mesh with triangles has that name or index (expected one of: {})",
                known.join(", ")
            ),
        });
    };
    let mut warnings = Vec::new();
    let resolved = mesh_job::resolve(&mut mesh.clone(), &sharpness, options, input, &mut warnings)?;
    let rows = explain_rows(&resolved.params, &resolved.topo);
    Ok(rows
        .iter()
        .map(ToString::to_string)
        .chain(warnings.iter().map(ToString::to_string))
        .collect())
}

/// One mesh's welded edges and the h resolved for each, as the surface would use them.
#[derive(Debug, Clone)]
pub struct ResolvedEdges {
    /// The glTF mesh.
    pub mesh: usize,
    /// Its welded adjacency (edge kinds, welded positions).
    pub topo: crate::topology::Topology,
    /// One h per edge of `topo`.
    pub h: Vec<f64>,
}

/// The h of every welded edge of every mesh of `doc` (read from `asset`), resolved from the
/// same sources and options as processing would: what the `h` picture draws.
pub fn resolved_edges(
    doc: &Document,
    asset: &Path,
    options: &Options,
) -> Result<Vec<ResolvedEdges>, Error> {
    let sharpness = asset_sharpness(doc, asset, options)?;
    // Meshes are independent, as in processing: resolved in parallel, collected in file order.
    mesh_inputs(doc, asset)?
        .into_par_iter()
        .map(|mut m| {
            let resolved = mesh_job::resolve(&mut m, &sharpness, options, asset, &mut Vec::new())?;
            Ok(ResolvedEdges {
                mesh: m.mesh,
                topo: resolved.topo,
                h: resolved.params.h,
            })
        })
        .collect()
}

/// Tangents are regenerated when the input had them, or when the primitive's material has a
/// normal texture (a renderer would otherwise derive them per pixel from screen derivatives,
/// which no longer match a bake against the low-poly mesh).
fn needs_tangents(doc: &Document, mesh: usize, prim: usize, data: &PrimitiveData) -> Option<u32> {
    match doc.normal_texture_set(mesh, prim) {
        Some(set) => Some(set),
        None if data.tangents().is_some() => Some(0),
        None => None,
    }
}

/// Peak memory of the whole per-file job per output triangle, in bytes, at the upper end: the
/// peak resident size of `g2tess` divided by the triangles written is 421 bytes on
/// DamagedHelmet at level 8 (UVs and regenerated tangents; 371 per added output triangle from
/// level 4), rounded up; positions and normals alone take about 35 per output triangle plus
/// about 320 per input triangle. It turns `--max-triangles` into a memory bound and sizes the
/// decoding budget.
pub const PEAK_BYTES_PER_OUTPUT_TRIANGLE: u64 = 512;

/// Refuses work whose output would not fit, from the declared sizes alone (before decoding or
/// allocating anything), and says what the level would produce and which level would fit.
///
/// Decoding is bounded too: the triangle primitives' arrays may take at most what the output
/// limit allows the whole job, so that many primitives sharing one large accessor cannot make
/// decoding alone exhaust memory.
fn check_output_size(
    doc: &Document,
    level: u32,
    options: &Options,
    asset: &Path,
) -> Result<(), Error> {
    let limit = options.max_output_triangles;
    let (mut tris, mut decoded) = (0u64, 0u64);
    for (mesh, prim) in doc.triangle_primitives() {
        let size = doc.primitive_size(mesh, prim);
        tris = tris.saturating_add(size.triangles);
        decoded = decoded.saturating_add(size.decoded_bytes);
    }
    let decode_budget = limit.saturating_mul(PEAK_BYTES_PER_OUTPUT_TRIANGLE);
    if decoded > decode_budget {
        return Err(Error::limit(
            asset,
            format!(
                "the triangle primitives decode to {} ({decoded} bytes), over the {} that --max-triangles {limit} allows (expected fewer or smaller primitives, or a larger --max-triangles)",
                gib(decoded),
                gib(decode_budget)
            ),
        ));
    }
    let out = |l: u32| tris.saturating_mul(u64::from(l) * u64::from(l));
    if out(level) <= limit {
        return Ok(());
    }
    let hint = match (1..level).rev().find(|l| out(*l) <= limit) {
        Some(l) => format!(
            "--level {l} would give {} triangles (about {})",
            out(l),
            gib(out(l).saturating_mul(PEAK_BYTES_PER_OUTPUT_TRIANGLE))
        ),
        None => format!("no level fits: even level 1 gives {tris} triangles"),
    };
    Err(Error::limit(
        asset,
        format!(
            "level {level} would produce {} triangles from {tris} (about {} of memory), over --max-triangles {limit} (expected {hint}, or a larger --max-triangles)",
            out(level),
            gib(out(level).saturating_mul(PEAK_BYTES_PER_OUTPUT_TRIANGLE))
        ),
    ))
}

/// `bytes` in GiB (or MiB when small), for messages.
fn gib(bytes: u64) -> String {
    const MIB: f64 = (1u64 << 20) as f64;
    let b = bytes as f64;
    if b >= 1024.0 * MIB {
        format!("{:.1} GiB", b / (1024.0 * MIB))
    } else {
        format!("{:.1} MiB", b / MIB)
    }
}
