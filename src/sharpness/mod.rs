//! Per-edge blend width h: resolves one h per welded edge of a mesh from the glTF `extras`, the
//! sidecar TOML, the crease-angle and hard-edge rules and the defaults, and says which source
//! won. It deliberately does not tessellate, does not read glTF files (the caller hands it each
//! mesh's `extras` as JSON values) and never prints: warnings and explanations are data.
//!
//! # Precedence
//!
//! The most specific source wins:
//!
//! 1. an `edges` entry in the sidecar;
//! 2. an `edges` entry in `extras`: the primitive's, then the mesh's;
//! 3. the crease-angle rule (an edge whose faces meet at more than the crease angle gets
//!    h = 0), then hard edges of the input (split normals) when `keep_hard_edges` is on;
//! 4. the `h` of the mesh's sidecar section;
//! 5. the `h` in a primitive's `extras`, else in the mesh's `extras`;
//! 6. the top-level `h` of the sidecar;
//! 7. the options (`--h`, `config/default.toml`).
//!
//! The rules (3) rank above every *default* h (4–7), not below the sidecar and extras defaults:
//! a block such as `h = 0.2, crease_angle = 60` means "smooth at 0.2, but keep edges sharper than
//! 60° sharp", which only holds if the rule beats the default next to it. Explicit edge entries
//! still beat the rule, so a single crease can be softened by naming it.
//!
//! The crease angle itself comes from the most specific block that sets one: the mesh's sidecar
//! section, the primitive's `extras`, the mesh's `extras`, the sidecar's top level, the options.
//!
//! An edge shared by two primitives whose values differ (their `extras` defaults or crease
//! angles) takes the sharper one: the smaller h, the smaller crease angle. A primitive without
//! its own value contributes the mesh's. Two *entries* for one edge at the same level (the same
//! sidecar, or the `extras` of two primitives) with different h are an error; the same value
//! twice is fine.
//!
//! # Naming edges
//!
//! `a`/`b` are vertex indices of one primitive (local to it, as in its accessors); `from`/`to`
//! are positions, matched against the welded vertices within [`DEFAULT_POSITION_TOLERANCE`]
//! times the diagonal of the mesh's bounding box, in either order.

mod effective;
mod entries;
mod error;
mod explain;
mod extras;
mod naming;
mod resolve;
mod rules;
mod sidecar;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub use effective::{EffectiveH, InvalidH};
pub use error::{Location, Problem, SharpnessError};
pub use explain::{explain_rows, ExplainRow, HSource};
pub use extras::EXTRAS_KEY;
pub use rules::{dihedral_degrees, is_crease, CREASE_SLACK_DEGREES};
pub use sidecar::{sidecar_path_for, DensityKeys, Sidecar, SIDECAR_SUFFIX};

use crate::mesh::TriMesh;
use crate::topology::{EdgeKind, Topology};
use entries::at;
use sidecar::MeshKey;

/// The largest blend width, √2/4: the surface's one definition, re-exported.
pub use crate::surface::H_MAX;

/// `from`/`to` positions match a welded vertex within this fraction of the mesh's bounding-box
/// diagonal: loose enough for float round trips through other tools, far below any edge length.
pub const DEFAULT_POSITION_TOLERANCE: f64 = 1e-5;

/// The defaults that apply where no file says otherwise, from the resolved options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Defaults {
    /// Blend width for edges no other source sets, in [0, [`H_MAX`]].
    pub h: f64,
    /// Crease angle in degrees, in [0, 180]; 180 turns the rule off.
    pub crease_angle: f64,
    /// Give hard edges of the input (split normals) h = 0.
    pub keep_hard_edges: bool,
}

/// One mesh as the pipeline combined it: all its triangle primitives in one [`TriMesh`].
#[derive(Debug, Clone, Copy)]
pub struct MeshContext<'a> {
    /// Index of the mesh in the asset.
    pub index: usize,
    pub name: Option<&'a str>,
    /// The mesh's `extras`, whole; only its `"g2tess"` key is read.
    pub extras: Option<&'a serde_json::Value>,
    /// The triangle primitives that went into the combined mesh.
    pub primitives: &'a [PrimitiveContext<'a>],
}

/// One triangle primitive inside the combined mesh.
///
/// Its vertices must sit in the combined mesh at `vertex_offset ..vertex_offset + vertex_count`,
/// in accessor order, so that `a`/`b` indices keep their meaning.
#[derive(Debug, Clone, Copy)]
pub struct PrimitiveContext<'a> {
    /// Index of the primitive in the mesh (also for non-triangle siblings that were skipped).
    pub index: usize,
    pub extras: Option<&'a serde_json::Value>,
    pub vertex_offset: u32,
    pub vertex_count: u32,
}

/// One h per welded edge (indexed by [`crate::topology::EdgeId`]), why, and what looked odd.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeParams {
    /// The h each edge's sources ask for (what `--explain-h` shows), in range; empty when the
    /// asset was made [`AssetSharpness::effective_only`].
    pub h: Vec<f64>,
    /// The h each edge is built with: `h` clamped to √2/4 on interior edges, 0 on boundary,
    /// non-manifold and degenerate ones. Decided once here; the surfaces, the tessellator's
    /// creases, the morph targets and the report all read it.
    pub effective: EffectiveH,
    /// Which source set each edge's h: one per edge when the asset was made
    /// [`AssetSharpness::with_sources`] (for `--explain-h`), else empty.
    pub sources: Vec<HSource>,
    pub warnings: Vec<SharpnessWarning>,
}

/// Something legal but probably not what the user meant.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SharpnessWarning {
    /// An edge entry asks for h > 0 on an edge the surface never blends.
    EntryOnUnblendedEdge {
        at: Location,
        /// The welded edge the entry names.
        edge: crate::topology::EdgeId,
        kind: EdgeKind,
        h: f64,
    },
}

impl std::fmt::Display for SharpnessWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SharpnessWarning::EntryOnUnblendedEdge { at, kind, h, .. } => {
                let kind = match kind {
                    EdgeKind::Interior => "an interior",
                    EdgeKind::Boundary => "a boundary",
                    EdgeKind::NonManifold => "a non-manifold",
                    EdgeKind::Degenerate => "a degenerate",
                };
                write!(
                    f,
                    "{at}: h = {h} has no effect on {kind} edge, which always uses h = 0"
                )
            }
        }
    }
}

/// The h sources of one asset: its path, its sidecar bound to its meshes, and the defaults.
#[derive(Debug, Clone)]
pub struct AssetSharpness {
    asset: PathBuf,
    sidecar: Option<Sidecar>,
    /// Mesh index → index into `sidecar.meshes`.
    section_of_mesh: HashMap<usize, usize>,
    defaults: Defaults,
    /// Whether [`EdgeParams::sources`] is filled: only `--explain-h` reads it, and at 32 bytes
    /// per edge it is not built otherwise.
    keep_sources: bool,
    /// Whether [`EdgeParams::h`] is filled: smoothing reads only the effective widths, and the
    /// requested ones (8 bytes per edge) are then not built.
    keep_requested: bool,
}

impl AssetSharpness {
    /// Checks the defaults and binds the sidecar's mesh sections to the asset's meshes (by index,
    /// or by name: unknown and ambiguous names, and two sections for one mesh, are errors).
    pub fn new(
        asset: &Path,
        sidecar: Option<Sidecar>,
        mesh_names: &[Option<&str>],
        defaults: Defaults,
    ) -> Result<Self, SharpnessError> {
        let mut defaults = defaults;
        defaults.h = entries::check_h(defaults.h).map_err(|p| at(&Location::Options, p))?;
        entries::check_crease_angle(defaults.crease_angle)
            .map_err(|p| at(&Location::Options, p))?;
        let mut section_of_mesh: HashMap<usize, usize> = HashMap::new();
        if let Some(sc) = &sidecar {
            for (s, section) in sc.meshes.iter().enumerate() {
                let here = Location::Toml {
                    file: sc.file.clone(),
                    line: section.line,
                    path: String::new(),
                };
                let mesh = bind_section(&section.key, mesh_names).map_err(|p| at(&here, p))?;
                if let Some(&other) = section_of_mesh.get(&mesh) {
                    let name = mesh_names.get(mesh).copied().flatten();
                    return Err(at(
                        &here,
                        Problem::DuplicateMeshSection {
                            mesh: mesh_label(mesh, name),
                            other_line: sc.meshes[other].line,
                        },
                    ));
                }
                section_of_mesh.insert(mesh, s);
            }
        }
        Ok(AssetSharpness {
            asset: asset.to_path_buf(),
            sidecar,
            section_of_mesh,
            defaults,
            keep_sources: false,
            keep_requested: true,
        })
    }

    /// The same, resolving each edge's [`HSource`] too (for `--explain-h`); without it
    /// [`EdgeParams::sources`] is empty.
    pub fn with_sources(mut self) -> Self {
        self.keep_sources = true;
        self
    }

    /// The same, leaving [`EdgeParams::h`] empty: for smoothing, which reads only
    /// [`EdgeParams::effective`]. Every effective width is the one a full resolution gives.
    /// Ignored where the sources are kept, which are explained beside the requested h.
    pub fn effective_only(mut self) -> Self {
        self.keep_requested = false;
        self
    }

    /// The per-asset tessellation level from the sidecar, if it sets one.
    pub fn level(&self) -> Option<u32> {
        self.sidecar.as_ref().and_then(Sidecar::level)
    }

    /// The options mesh `mesh` is tessellated with: `options` (flags, folder config,
    /// `--config`) under the sidecar's top-level density keys, under the mesh section's.
    pub fn mesh_options(
        &self,
        mesh: usize,
        options: &crate::options::Options,
    ) -> crate::options::Options {
        let Some(sc) = &self.sidecar else {
            return options.clone();
        };
        let asset = sc.density.apply(options.clone());
        match self.section_of_mesh.get(&mesh) {
            Some(&s) => sc.meshes[s].density.apply(asset),
            None => asset,
        }
    }

    /// The options of each level of mesh `mesh`'s LOD chain, finest first (empty without a
    /// chain): the chain's level ([`crate::options::Options::lod_levels`]) under the sidecar's
    /// density keys as in [`Self::mesh_options`]. A block that decides its scope's density
    /// fixes it at every level, so such a mesh's levels are all one (written once).
    pub fn mesh_lod_levels(
        &self,
        mesh: usize,
        options: &crate::options::Options,
    ) -> Vec<crate::options::Options> {
        options
            .lod_levels()
            .iter()
            .map(|level| self.mesh_options(mesh, level))
            .collect()
    }

    /// Whether the sidecar sets a density key anywhere (then meshes may differ in density).
    pub fn sets_density(&self) -> bool {
        self.sidecar.as_ref().is_some_and(|sc| {
            sc.density != DensityKeys::default()
                || sc
                    .meshes
                    .iter()
                    .any(|m| m.density != DensityKeys::default())
        })
    }

    /// The sidecar in use, if any.
    pub fn sidecar(&self) -> Option<&Sidecar> {
        self.sidecar.as_ref()
    }

    /// Resolves one h per edge of `topo` (built from `mesh`) for the mesh described by `ctx`.
    pub fn resolve_mesh(
        &self,
        ctx: &MeshContext<'_>,
        mesh: &TriMesh,
        topo: &Topology,
    ) -> Result<EdgeParams, SharpnessError> {
        resolve::resolve(self, ctx, mesh, topo, true)
    }

    /// [`Self::resolve_mesh`] without the widths: every edge entry is bound to its edge and
    /// checked, with the same errors and warnings, but no edge's h is picked, so
    /// [`EdgeParams::h`], [`EdgeParams::effective`] and [`EdgeParams::sources`] are empty.
    ///
    /// For a run that reads no width: a uniform level 1 writes the input's corners whatever
    /// the h, and picking each edge's h (the crease rule's face normals and angles) was about
    /// a fifth of such a run on a million triangles.
    pub fn check_mesh(
        &self,
        ctx: &MeshContext<'_>,
        mesh: &TriMesh,
        topo: &Topology,
    ) -> Result<EdgeParams, SharpnessError> {
        resolve::resolve(self, ctx, mesh, topo, false)
    }
}

fn bind_section(key: &MeshKey, names: &[Option<&str>]) -> Result<usize, Problem> {
    match key {
        MeshKey::Index(i) if *i < names.len() => Ok(*i),
        MeshKey::Index(i) => Err(Problem::NoSuchMeshIndex {
            index: *i,
            count: names.len(),
        }),
        MeshKey::Name(name) => {
            let hits: Vec<usize> = (0..names.len())
                .filter(|&i| names[i] == Some(name.as_str()))
                .collect();
            match hits.as_slice() {
                [i] => Ok(*i),
                [] => {
                    let mut known: Vec<String> = names
                        .iter()
                        .flatten()
                        .take(8)
                        .map(|n| format!("{n:?}"))
                        .collect();
                    if names.iter().flatten().count() > known.len() {
                        known.push("…".to_string());
                    }
                    if known.is_empty() {
                        known.push("none named".to_string());
                    }
                    Err(Problem::NoSuchMeshName {
                        name: name.clone(),
                        known: known.join(", "),
                    })
                }
                [first, ..] => Err(Problem::AmbiguousMeshName {
                    name: name.clone(),
                    indices: hits
                        .iter()
                        .map(|i| i.to_string())
                        .collect::<Vec<_>>()
                        .join(", "),
                    first: *first,
                }),
            }
        }
    }
}

/// `mesh "Body"` for a named mesh, `mesh 3` otherwise.
pub(crate) fn mesh_label(index: usize, name: Option<&str>) -> String {
    match name {
        Some(name) => format!("mesh {name:?}"),
        None => format!("mesh {index}"),
    }
}
