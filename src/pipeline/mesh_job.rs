//! One mesh through every stage: join its triangle primitives, weld, resolve h, build the
//! surface, tessellate, carry attributes and morph targets, order for the GPU, split back into
//! primitives.
//!
//! It deliberately does not touch the document: it takes decoded arrays and returns new ones,
//! so meshes can run in parallel and the caller writes them back in file order.

use std::ops::Range;
use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use serde_json::Value;

use super::density::Density;
use super::error::Error;
use super::morph;
use super::primitive_out::{self, Prepared};
use super::report::{EdgeFigures, LodReport, MeshReport, PrimitiveReport};
use super::warning::{merge_target_warnings, Warning};
use crate::gltf_io::{self, semantic, PrimitiveData, Values};
use crate::mesh::TriMesh;
use crate::options::Options;
use crate::sharpness::{AssetSharpness, EdgeParams, EffectiveH, MeshContext, PrimitiveContext};
use crate::surface::flat::flat_is_exact;
use crate::surface::{scheme, FlatSurface, G2Surface, Scheme, Surface};
use crate::topology::Topology;
use crate::{normals, optimize};

/// One triangle primitive as read.
#[derive(Debug, Clone)]
pub struct PrimitiveInput {
    /// Its index in the glTF mesh.
    pub index: usize,
    /// Its `extras`, for per-edge h.
    pub extras: Option<Value>,
    /// `Some(texcoord set)` when tangents must be generated (see the pipeline's rule).
    pub needs_tangents: Option<u32>,
    /// The accessor of its NORMAL, named in the warning about repaired normals.
    pub normal_accessor: Option<usize>,
    /// The decoded arrays.
    pub data: PrimitiveData,
}

/// One glTF mesh's triangle primitives as read.
#[derive(Debug, Clone)]
pub struct MeshInput {
    /// Its index in the document.
    pub mesh: usize,
    /// Its name, for sidecar sections and messages.
    pub name: Option<String>,
    /// Its `extras`, for per-edge h.
    pub extras: Option<Value>,
    /// Its triangle primitives, in file order.
    pub primitives: Vec<PrimitiveInput>,
}

/// The replacement primitives of one mesh and what it took.
#[derive(Debug, Clone)]
pub struct MeshOutput {
    /// (primitive index, new data), in file order: the finest level.
    pub primitives: Vec<(usize, PrimitiveData)>,
    /// The coarser levels of a LOD chain, finest first, each as `primitives` is; `None` where
    /// a level's counts equal the level before's (the same output, made and written once).
    pub lods: Vec<Option<Vec<(usize, PrimitiveData)>>>,
    /// Counts, timings, continuity, warnings.
    pub report: MeshReport,
    /// The diagonal of the mesh's bounding box, which the LOD chain's coverage hints scale by.
    pub diagonal: f64,
}

/// A mesh welded and with its h resolved: what every later stage starts from.
pub(super) struct Resolved {
    /// Each primitive, checked (and with generated normals where it had none).
    pub prepared: Vec<Prepared>,
    /// All primitives joined.
    pub mesh: TriMesh,
    /// Each primitive's triangles in `mesh`.
    pub groups: Vec<Range<usize>>,
    /// Adjacency of `mesh`.
    pub topo: Topology,
    /// One h per welded edge, with where each came from; no widths where none are read.
    pub params: EdgeParams,
    /// Whether anything reads the widths (see [`widths_read`]): without, `params` holds none.
    pub widths_read: bool,
}

/// Checks and joins the primitives of `input`, welds them and resolves per-edge h; warnings
/// go to `warnings`. The primitives' decoded arrays move out of `input` (into the result).
pub(super) fn resolve(
    input: &mut MeshInput,
    sharpness: &AssetSharpness,
    options: &Options,
    asset: &Path,
    warnings: &mut Vec<Warning>,
) -> Result<Resolved, Error> {
    resolve_for(input, sharpness, options, false, asset, warnings)
}

/// [`resolve`] for a tessellation that reads corners alone where `corners_only` (see
/// [`surface_for`]): then, where nothing else reads them, no edge's h is picked (the entries
/// are still checked).
fn resolve_for(
    input: &mut MeshInput,
    sharpness: &AssetSharpness,
    options: &Options,
    corners_only: bool,
    asset: &Path,
    warnings: &mut Vec<Warning>,
) -> Result<Resolved, Error> {
    let mut prepared: Vec<Prepared> = Vec::with_capacity(input.primitives.len());
    for p in &mut input.primitives {
        let data = std::mem::replace(
            &mut p.data,
            PrimitiveData {
                attributes: Vec::new(),
                indices: Vec::new(),
                targets: Vec::new(),
            },
        );
        let prep = prepare(input.mesh, p, data, options.crease_angle, warnings)
            .map_err(|e| Error::gltf(asset, e))?;
        prepared.push(prep);
    }
    assign_offsets(&mut prepared);
    // Before the join, which moves the primitives' vertices out.
    let contexts: Vec<PrimitiveContext> = input
        .primitives
        .iter()
        .zip(&prepared)
        .map(|(p, prep)| PrimitiveContext {
            index: p.index,
            extras: p.extras.as_ref(),
            vertex_offset: prep.vertex_offset,
            vertex_count: prep.vertex_count(),
        })
        .collect();
    let (mesh, groups) = join(&mut prepared);
    if mesh.triangles.len() > crate::topology::MAX_TRIANGLES {
        return Err(Error::limit(
            asset,
            format!(
                "mesh {} has {} triangles, over the {} one mesh can hold (expected it split into several meshes)",
                input.mesh,
                mesh.triangles.len(),
                crate::topology::MAX_TRIANGLES
            ),
        ));
    }
    let topo = Topology::build(&mesh);
    let widths_read = widths_read(options, corners_only, &mesh, &prepared);
    let ctx = MeshContext {
        index: input.mesh,
        name: input.name.as_deref(),
        extras: input.extras.as_ref(),
        primitives: &contexts,
    };
    // The geometry checks only report: they run beside the resolution of h.
    let (checks, params) = rayon::join(
        || super::checks::mesh_warnings(input.mesh, &mesh, &topo),
        || {
            if widths_read {
                sharpness.resolve_mesh(&ctx, &mesh, &topo)
            } else {
                sharpness.check_mesh(&ctx, &mesh, &topo)
            }
        },
    );
    warnings.extend(checks);
    let params = params?;
    warnings.extend(
        params
            .warnings
            .iter()
            .map(|w| Warning::from_sharpness(input.mesh, w)),
    );
    Ok(Resolved {
        prepared,
        mesh,
        groups,
        topo,
        params,
        widths_read,
    })
}

/// Whether any stage reads the mesh's blend widths. Only a run that tessellates on the flat
/// surface and writes no report reads none: at a uniform level 1 every output vertex is an
/// input corner, numbered by input vertex and written from the mesh (the tessellator's creases
/// split only edge samples, and there are none), so the widths change no output bit. The
/// report's edge counts read them ([`Options::report_figures`] asks for a report), as do the
/// surfaces of morph targets and every other surface.
fn widths_read(
    options: &Options,
    corners_only: bool,
    mesh: &TriMesh,
    prepared: &[Prepared],
) -> bool {
    let targets = prepared.iter().any(|p| !p.data.targets.is_empty());
    options.report_figures || targets || !takes_flat_surface(options, corners_only, mesh)
}

/// Smooths one mesh at `level`; its decoded arrays are freed as they are used.
pub fn smooth_mesh(
    mut input: MeshInput,
    sharpness: &AssetSharpness,
    level: u32,
    options: &Options,
    asset: &Path,
) -> Result<MeshOutput, Error> {
    let mut report = MeshReport {
        mesh: input.mesh,
        name: input.name.clone(),
        ..MeshReport::default()
    };
    stop_if_cancelled(options, asset)?;
    // One level, or every level of the LOD chain from the one surface: only the counts and
    // the tessellation are per level.
    // The sidecar's density keys apply to each level as to one: a block that decides its
    // mesh's density fixes it at every level.
    let chain = sharpness.mesh_lod_levels(input.mesh, options);
    // Only a single uniform level 1 with nothing measured reads corners alone.
    let corners_only =
        chain.is_empty() && !options.adaptive() && level == 1 && !options.report_figures;
    let clock = Instant::now();
    let Resolved {
        prepared,
        mesh,
        groups,
        topo,
        params,
        widths_read,
    } = resolve_for(
        &mut input,
        sharpness,
        options,
        corners_only,
        asset,
        &mut report.warnings.0,
    )?;
    report.times.sharpness = lap(&clock, 0.0);
    stop_if_cancelled(options, asset)?;
    // Only the effective widths are read from here on: the requested h and where each came
    // from (for `--explain-h`) are freed before the surface, the run's peak, is built.
    let EdgeParams {
        effective,
        h,
        sources,
        ..
    } = params;
    drop((h, sources));

    // Where no width is read the flat surface is the one `surface_for` would take (the same
    // test decided it), without testing every normal again.
    let (surface, surface_warnings) = if widths_read {
        // One uniform level with nothing measured reads the surface once, in triangle order.
        let one_pass = chain.is_empty() && !options.adaptive() && !options.report_figures;
        surface_for(options, corners_only, one_pass, &mesh, &topo, &effective)
    } else {
        let flat: Box<dyn Surface> = Box::new(FlatSurface::new(&mesh));
        (flat, Vec::new())
    };
    report.warnings.0.extend(
        surface_warnings
            .iter()
            .map(|w| Warning::from_surface(input.mesh, None, w)),
    );
    report.edges = if options.report_figures {
        EdgeFigures::measure(surface.as_ref(), &topo, &effective)
    } else if widths_read {
        EdgeFigures::count(&topo, &effective)
    } else {
        // Nothing reads the counts: no report is written.
        EdgeFigures::default()
    };
    report.times.surface = lap(&clock, report.times.sharpness);
    stop_if_cancelled(options, asset)?;

    let is_chain = !chain.is_empty();
    let levels = if chain.is_empty() {
        vec![options.clone()]
    } else {
        chain
    };
    let mut primitives = Vec::new();
    let mut lods = Vec::new();
    let mut previous: Option<Density> = None;
    // Every level written is held (and, with MSFT_lod, stored in the one file): the limit is
    // on their sum.
    let mut planned_total = 0u64;
    // The G² surface holds about 88 bytes per input triangle: freed once the last level's
    // vertices are evaluated, before its triangles are written and its attributes carried.
    let mut surface = Some(surface);
    let last = levels.len() - 1;
    for (k, level_options) in levels.iter().enumerate() {
        let tess_start = Instant::now();
        let live = surface.as_deref().expect("freed after the last level only");
        let density = Density::choose(
            level_options,
            level,
            &mesh,
            &topo,
            &effective,
            live,
            &groups,
        );
        if previous.as_ref().is_some_and(|p| p.same_output(&density)) {
            // A looser tolerance (or a larger budget) that changes no count: a flat mesh at one
            // segment per edge, say, or a sidecar that fixes the mesh's density. The level
            // before is this level.
            let mut same = report.lod[k - 1].clone();
            same.level = k;
            if let Density::Counts { target, .. } = &density {
                same.figures.tolerance = *target;
            }
            same.triangle_budget =
                (level_options.triangle_budget > 0).then_some(level_options.triangle_budget);
            report.lod.push(same);
            lods.push(None);
            continue;
        }
        let planned = density.triangle_count(&mesh, &topo);
        previous = Some(density.clone());
        planned_total = planned_total.saturating_add(planned);
        if planned_total > options.max_output_triangles {
            let what = if is_chain {
                format!("levels 0 to {k} of its LOD chain would get {planned_total} triangles")
            } else {
                format!("would get {planned} triangles")
            };
            return Err(Error::limit(
                asset,
                format!(
                    "mesh {} {what}, over --max-triangles {} (expected a larger tolerance, a --triangle-budget or a larger --max-triangles)",
                    input.mesh, options.max_output_triangles
                ),
            ));
        }
        let tessellation = density.tessellate(&mesh, &topo, &effective, live, &groups);
        // Unless the report measures the output against it, the surface is done with before
        // the output's triangles and vertex sources are written: they are not held together.
        if k == last && !options.report_figures {
            surface = None;
        }
        let mut dense = tessellation.finish();
        report.times.tessellate += tess_start.elapsed().as_secs_f64();
        // Measured for the report only, as for one level: the output never depends on it.
        let figures = density.figures(
            &topo,
            surface.as_deref(),
            &groups,
            &dense,
            options.report_figures,
        );
        if k == last {
            surface = None;
        }
        stop_if_cancelled(options, asset)?;

        // The tessellator already emits cache-friendly bands with vertices in first-use order:
        // meshoptimizer's vertex cache pass made both figures worse on its output and took
        // longer than the tessellation (see `optimize.rs`). Only overdraw ordering remains.
        let opt_start = Instant::now();
        let remaps: Vec<Option<Vec<u32>>> = dense
            .iter_mut()
            .map(|d| options.overdraw.then(|| optimize::order_for_overdraw(d)))
            .collect();
        report.times.optimize += opt_start.elapsed().as_secs_f64();

        let attr_start = Instant::now();
        let (targets, target_warnings) = morph::targets(
            &mesh, &topo, &effective, &prepared, &groups, &density, options, &remaps,
        );
        if k == 0 {
            // Every level's targets are made by the same surfaces: their warnings once.
            let target_warnings = target_warnings
                .iter()
                .map(|(t, w)| Warning::from_surface(input.mesh, Some(*t), w))
                .collect();
            merge_target_warnings(&mut report.warnings.0, target_warnings);
        }
        let mut level_primitives = Vec::with_capacity(prepared.len());
        let (mut triangles, mut vertices) = (0, 0);
        for (j, ((prep, d), target)) in prepared.iter().zip(dense).zip(targets).enumerate() {
            triangles += d.indices.len() / 3;
            vertices += d.positions.len();
            if k == 0 {
                report.primitives.push(PrimitiveReport {
                    primitive: input.primitives[j].index,
                    triangles_in: groups[j].len(),
                    vertices_in: prep.source_vertex_count,
                    triangles_out: d.indices.len() / 3,
                    vertices_out: d.positions.len(),
                    cache: options.report_figures.then(|| optimize::cache_figures(&d)),
                });
            }
            let data = primitive_out::build(
                prep,
                d,
                &mesh.triangles[groups[j].clone()],
                groups[j].start as u32,
                target,
            );
            refuse_non_finite(&data, input.mesh, input.primitives[j].index, options)
                .map_err(|e| Error::gltf(asset, e))?;
            level_primitives.push((input.primitives[j].index, data));
        }
        report.times.attributes += attr_start.elapsed().as_secs_f64();
        if is_chain {
            report.lod.push(LodReport {
                level: k,
                triangle_budget: (level_options.triangle_budget > 0)
                    .then_some(level_options.triangle_budget),
                triangles,
                vertices,
                figures: figures.clone().unwrap_or_default(),
                mesh: None,
            });
        }
        if k == 0 {
            report.adaptive = figures;
            primitives = level_primitives;
        } else {
            lods.push(Some(level_primitives));
        }
    }
    let diagonal = super::density::diagonal(&mesh);
    // The mesh's own arrays (its topology, joined vertices and prepared primitives: about 150
    // bytes per input triangle) are unmapped on two threads instead of one: the pages of each
    // are freed beside the other's. On a million triangles this was a serial 13 ms at the end
    // of the job, with the other thread idle. Both are freed before the output is stored, so
    // the peak is unchanged (a task left to free them later raised it when the machine was
    // busy).
    drop(surface);
    rayon::join(
        move || drop(topo),
        move || drop((mesh, prepared, effective, groups)),
    );
    Ok(MeshOutput {
        primitives,
        lods,
        report,
        diagonal,
    })
}

/// No output value is ever non-finite: a surface that overflows f32 (coordinates near its
/// largest value, where a scheme's control points leave the range) fails the file with the
/// primitive and attribute named, instead of writing Infinity or NaN that the validator rejects.
fn refuse_non_finite(
    data: &PrimitiveData,
    mesh: usize,
    prim: usize,
    options: &Options,
) -> Result<(), gltf_io::Error> {
    let at = format!("meshes[{mesh}].primitives[{prim}]");
    let lists = data.attributes.iter().map(|a| (a, String::new())).chain(
        data.targets
            .iter()
            .enumerate()
            .flat_map(|(t, attrs)| attrs.iter().map(move |a| (a, format!("targets[{t}].")))),
    );
    for (a, target) in lists {
        let Some(v) = a.floats() else {
            continue;
        };
        // Every value of a dense mesh is checked: in parallel chunks, each by a branch-free
        // fold the compiler vectorizes (a search that stops at the first hit is not), and the
        // first bad value looked for only where there is one.
        let finite = |c: &[f32]| c.iter().fold(true, |ok, x| ok & x.is_finite());
        if v.par_chunks(1 << 16).all(finite) {
            continue;
        }
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(gltf_io::Error::invalid(
                format!("{at}.{target}attributes.{}", a.name),
                format!(
                    "the {} surface reaches {} at output vertex {} (expected finite 32-bit floats; the input's coordinates are too close to the largest float for this scheme: scale the mesh down)",
                    options.scheme.name(),
                    v[i],
                    i / a.components.max(1)
                ),
            ));
        }
    }
    Ok(())
}

/// [`Error::Cancelled`] once the caller's stop flag is set: polled between stages, so a stop
/// waits at most for one stage of one mesh.
pub(super) fn stop_if_cancelled(options: &Options, asset: &Path) -> Result<(), Error> {
    if options.cancel.requested() {
        return Err(Error::Cancelled {
            file: asset.to_path_buf(),
        });
    }
    Ok(())
}

/// Seconds since `clock` minus what earlier stages already took.
fn lap(clock: &Instant, before: f64) -> f64 {
    clock.elapsed().as_secs_f64() - before
}

/// The surface the options ask for, with the warnings its construction gave. `one_pass`: the
/// caller reads it once, in triangle order (one uniform level); the G² surface may then make
/// its patches on demand ([`G2Surface::with_nets_for_one_pass`]), with the same output bits.
pub(super) fn build_surface<'a>(
    options: &Options,
    one_pass: bool,
    mesh: &'a TriMesh,
    topo: &'a Topology,
    h: &'a EffectiveH,
) -> (Box<dyn Surface + 'a>, Vec<scheme::Warning>) {
    let params = options.scheme_params();
    if one_pass && options.scheme == Scheme::G2 {
        let surface = G2Surface::with_nets_for_one_pass(mesh, topo, h, params.profile, params.nets);
        return (Box::new(surface), Vec::new());
    }
    scheme::build_surface(options.scheme, mesh, topo, h, &params)
}

/// The surface to tessellate `mesh` on, with the warnings its construction gave: the one the
/// options ask for, or, when the tessellation reads `corners_only` (a uniform level 1), the
/// flat surface wherever no output bit can tell them apart.
///
/// At level 1 every output vertex is an input corner, written from the mesh itself (its
/// position and normalized normal) without asking the surface unless the normal has no
/// direction ([`crate::surface::flat`]). The G² and PN nets would then be built (about a third
/// of a level-1 run on a million triangles) and never read. Hybrid and Coons surfaces are
/// still built: their construction reports folded edges, which a run prints.
pub(super) fn surface_for<'a>(
    options: &Options,
    corners_only: bool,
    one_pass: bool,
    mesh: &'a TriMesh,
    topo: &'a Topology,
    h: &'a EffectiveH,
) -> (Box<dyn Surface + 'a>, Vec<scheme::Warning>) {
    if takes_flat_surface(options, corners_only, mesh) {
        return (Box::new(FlatSurface::new(mesh)), Vec::new());
    }
    build_surface(options, one_pass, mesh, topo, h)
}

/// Whether [`surface_for`] takes the flat surface for `mesh`: corners alone are read, the
/// scheme's construction reports nothing, and every input normal has a direction.
fn takes_flat_surface(options: &Options, corners_only: bool, mesh: &TriMesh) -> bool {
    let interpolates_silently = matches!(options.scheme, Scheme::G2 | Scheme::Pn);
    corners_only && interpolates_silently && flat_is_exact(mesh)
}

/// Checks a primitive's positions and normals, generating normals where there are none.
///
/// Takes the primitive's arrays: they move into the result instead of being copied, and the
/// positions and normals, converted to f64 here for the surface, leave them (only their names
/// and the input normals' exact bits are read later), so no per-vertex array is held twice.
fn prepare(
    mesh: usize,
    input: &PrimitiveInput,
    data: PrimitiveData,
    crease_angle: f64,
    warnings: &mut Vec<Warning>,
) -> Result<Prepared, gltf_io::Error> {
    let at = format!("meshes[{mesh}].primitives[{}]", input.index);
    let positions = data.positions(&at)?;
    let vertex_count = positions.len() / 3;
    let out_of_range =
        gltf_io::accessor::first_in_blocks(&data.indices, |&i| i as usize >= vertex_count);
    if let Some(bad) = out_of_range.map(|k| data.indices[k]) {
        return Err(gltf_io::Error::invalid(
            format!("{at}.indices"),
            format!("index {bad} is out of range (expected below the vertex count {vertex_count})"),
        ));
    }
    let triangles: Vec<[u32; 3]> = data
        .indices
        .par_chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let points: Vec<DVec3> = positions
        .par_chunks_exact(3)
        .map(|p| DVec3::new(p[0].into(), p[1].into(), p[2].into()))
        .collect();
    let prepared = match data.normals() {
        Some(n) => {
            let raw =
                |v: usize| DVec3::new(n[3 * v].into(), n[3 * v + 1].into(), n[3 * v + 2].into());
            let mut normals: Vec<DVec3> = (0..n.len() / 3)
                .into_par_iter()
                .map(|v| raw(v).normalize_or_zero())
                .collect();
            // One pass finds both the rescaled normals and the broken ones.
            let NormalFlaws {
                rescaled: count,
                first_rescaled: first,
                broken,
            } = NormalFlaws::of(&normals, raw);
            if let Some(first) = first {
                warnings.push(Warning::NormalsRescaled {
                    mesh,
                    primitive: input.index,
                    accessor: input.normal_accessor,
                    count,
                    vertex: first,
                    length: raw(first).length() as f32,
                });
            }
            if let Some(&first) = broken.first() {
                repair_normals(&points, &triangles, &broken, &mut normals);
                warnings.push(Warning::NormalsRepaired {
                    mesh,
                    primitive: input.index,
                    accessor: input.normal_accessor,
                    count: broken.len(),
                    vertex: first,
                });
            }
            Prepared::new(data, points, normals, triangles, input.needs_tangents)
        }
        None => {
            let generated = normals::generate(&points, &triangles, crease_angle);
            warnings.push(Warning::NormalsGenerated {
                mesh,
                primitive: input.index,
                crease_angle,
            });
            Prepared::with_generated_normals(&data, &points, generated, input.needs_tangents)
        }
    };
    Ok(without_core_values(prepared))
}

/// `prepared` with the f32 positions, normals and indices of its input arrays freed: from here
/// on they are read from the f64 copies and the triangle list (and the input normals' bits from
/// `exact_normals`), while the attributes keep their names and order, which the output follows.
fn without_core_values(mut prepared: Prepared) -> Prepared {
    for a in &mut prepared.data.attributes {
        if a.name == semantic::POSITION || a.name == semantic::NORMAL {
            a.values = match a.values {
                Values::Float(_) => Values::Float(Vec::new()),
                Values::Uint(_) => Values::Uint(Vec::new()),
            };
        }
    }
    prepared.data.indices = Vec::new();
    prepared
}

/// What is wrong with a primitive's input normals, found in one parallel pass.
#[derive(Debug, Default)]
struct NormalFlaws {
    /// How many were not unit length to the validator (but not zero): they were rescaled.
    rescaled: usize,
    /// The first of those.
    first_rescaled: Option<usize>,
    /// Every vertex whose normal is zero or not finite (to repair), in order.
    broken: Vec<usize>,
}

impl NormalFlaws {
    /// `normals[v]` is `raw(v)` normalized (zero where it cannot be). The parts are folded in
    /// vertex order and joined left to right, so the result does not depend on the threads.
    fn of(normals: &[DVec3], raw: impl Fn(usize) -> DVec3 + Sync) -> NormalFlaws {
        (0..normals.len())
            .into_par_iter()
            .fold(NormalFlaws::default, |mut f, v| {
                let n = normals[v];
                if n != DVec3::ZERO && !unit_to_validator(raw(v)) {
                    f.rescaled += 1;
                    f.first_rescaled = f.first_rescaled.or(Some(v));
                }
                if n == DVec3::ZERO || !n.is_finite() {
                    f.broken.push(v);
                }
                f
            })
            .reduce(NormalFlaws::default, |mut a, mut b| {
                a.rescaled += b.rescaled;
                a.first_rescaled = a.first_rescaled.or(b.first_rescaled);
                a.broken.append(&mut b.broken);
                a
            })
    }
}

/// Whether `n` is unit length within the Khronos validator's tolerance for unit vectors.
fn unit_to_validator(n: DVec3) -> bool {
    (n.length() - 1.0).abs() <= 0.00769
}

/// Replaces `normals[v]` for every `v` in `broken` (sorted) by the angle-weighted sum of the
/// unit normals of the faces around input vertex `v`, normalized (+Z where every face is
/// degenerate): one pass over the triangles, whatever the number of broken normals.
fn repair_normals(
    points: &[DVec3],
    triangles: &[[u32; 3]],
    broken: &[usize],
    normals: &mut [DVec3],
) {
    let mut is_broken = vec![false; normals.len()];
    for &v in broken {
        is_broken[v] = true;
    }
    let mut sums = vec![DVec3::ZERO; normals.len()];
    for t in triangles {
        if !t.iter().any(|&v| is_broken[v as usize]) {
            continue;
        }
        let p = t.map(|v| points[v as usize]);
        let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            let v = t[k] as usize;
            if is_broken[v] {
                let angle = (p[(k + 1) % 3] - p[k]).angle_between(p[(k + 2) % 3] - p[k]);
                if angle.is_finite() {
                    sums[v] += angle * face;
                }
            }
        }
    }
    for &v in broken {
        normals[v] = sums[v].normalize_or(DVec3::Z);
    }
}

/// The primitives of one mesh as one [`TriMesh`], and each primitive's triangle range in it.
fn join(prepared: &mut [Prepared]) -> (TriMesh, Vec<Range<usize>>) {
    // Positions, normals and triangles move into the joined mesh (nothing reads them from the
    // primitives afterwards; the attributes are carried through the mesh's triangles): a lone
    // primitive's are taken whole, several are copied into arrays sized once and freed one by
    // one, so no copy outlives the join.
    if let [p] = prepared {
        // Its vertex offset is 0: its triangles are the mesh's as they are.
        let mesh = TriMesh {
            positions: std::mem::take(&mut p.positions),
            normals: std::mem::take(&mut p.normals),
            triangles: std::mem::take(&mut p.triangles),
        };
        let all = 0..mesh.triangles.len();
        return (mesh, vec![all]);
    }
    let vertices: usize = prepared.iter().map(|p| p.positions.len()).sum();
    let triangles: usize = prepared.iter().map(|p| p.triangles.len()).sum();
    let mut mesh = TriMesh {
        triangles: Vec::with_capacity(triangles),
        ..TriMesh::default()
    };
    mesh.positions.reserve_exact(vertices);
    mesh.normals.reserve_exact(vertices);
    let mut groups = Vec::with_capacity(prepared.len());
    for p in prepared {
        let offset = p.vertex_offset;
        if !p.positions.is_empty() || !p.normals.is_empty() {
            debug_assert_eq!(offset as usize, mesh.positions.len());
            mesh.positions.append(&mut p.positions);
            mesh.normals.append(&mut p.normals);
            p.positions = Vec::new();
            p.normals = Vec::new();
        }
        let start = mesh.triangles.len();
        mesh.triangles
            .extend(p.triangles.iter().map(|t| t.map(|v| v + offset)));
        p.triangles = Vec::new();
        groups.push(start..mesh.triangles.len());
    }
    (mesh, groups)
}

/// Vertex offsets of each prepared primitive in the joined mesh.
fn assign_offsets(prepared: &mut [Prepared]) {
    let mut offset = 0u32;
    for p in prepared {
        p.vertex_offset = offset;
        offset += p.vertex_count();
    }
}
