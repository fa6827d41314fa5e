//! g2tess: dense, watertight, G²-smooth tessellation of glTF triangle meshes.
//!
//! # Code map
//!
//! The file tree is the architecture. Data flows top to bottom:
//!
//! - [`gltf_io`]: reads `.gltf`/`.glb` into a [`gltf_io::Document`] (JSON root plus decoded
//!   buffers, everything kept) and writes it back. The only module that speaks glTF.
//! - [`mesh`]: the core's mesh type, [`mesh::TriMesh`] (positions, unit normals, triangles).
//! - [`topology`]: welds vertices by position into one adjacency ([`topology::Topology`]);
//!   finds boundary, non-manifold, degenerate and split-normal edges and each triangle edge's
//!   neighbour.
//! - [`sharpness`]: resolves one blend width `h` per welded edge from glTF extras, sidecar TOML,
//!   the crease-angle rule and the defaults, and decides once the width each edge is built with
//!   ([`sharpness::EffectiveH`]: 0 on every edge the surface cannot blend).
//! - [`normals`]: vertex normals for meshes that come without them.
//! - [`surface`]: the smooth surfaces over a whole mesh behind the [`surface::Surface`] trait
//!   ([`surface::PnSurface`], [`surface::G2Surface`] (the G² blend of Lee–Hwang–Yoon), and the
//!   `hybrid` and `coons` schemes chosen with [`surface::Scheme`]), evaluated with exact normals
//!   at any domain point of any triangle, or over a whole lattice with cached weights; the
//!   control nets under `g2` and `pn` come from [`surface::nets`] (round by default, the paper's
//!   PN nets on request).
//! - [`continuity`]: measures position gap, normal jump and curvature jump across edges
//!   ([`continuity::measure`]).
//! - [`tessellate`]: the level-n lattice of every triangle, shared edge and corner samples
//!   evaluated once (watertight), output vertices split where the input was.
//! - [`attributes`]: carries texture coordinates, colors, skin weights and IDs to new vertices.
//! - [`tangents`]: MikkTSpace tangents for the dense output.
//! - [`optimize`]: meshoptimizer's vertex cache and fetch ordering.
//! - [`options`]: the resolved settings that flow down through every stage.
//! - [`pipeline`]: one file in, one file out; [`pipeline::process_document`] joins the stages;
//!   each fallback a stage takes reaches its report as a typed [`pipeline::Warning`];
//!   [`pipeline::lod`] stores a LOD chain (`MSFT_lod` meshes and nodes via [`gltf_io::lod`], or
//!   one document per level).
//! - [`render`]: pictures of any document on the CPU (shaded, zebra, flat, and the input's
//!   edges coloured by h), side by side with one camera, as PNG.
//!
//! **Architecture invariant:** [`mesh`], [`topology`], [`surface`], [`continuity`],
//! [`tessellate`], [`attributes`] and [`normals`] take slices
//! and return values; they know nothing of glTF, files, clap or meshopt, and never fail on bad
//! geometry (they fall back and report).
//!
//! **Architecture invariant:** the library never sees clap, walkdir or notify; those live in the
//! binary (`src/main.rs`, `src/cli/`).

pub mod attributes;
pub mod continuity;
pub mod gltf_io;
pub mod mesh;
pub mod normals;
pub mod optimize;
pub mod options;
pub mod pipeline;
pub mod render;
pub mod sharpness;
pub mod surface;
pub mod tangents;
pub mod tessellate;
pub mod topology;
