//! Pictures of glTF scenes, drawn on the CPU: a small deterministic software rasterizer that
//! shows what the numbers of a report cannot, a kink in the reflection lines or a crease that
//! should not be there.
//!
//! - [`scene`]: the default scene's triangles in world space, node transforms applied.
//! - [`camera`]: orthographic cameras framed on bounds, one per [`View`].
//! - [`raster`]: the z-buffer (nearest triangle and depth per pixel), in parallel bands.
//! - [`shade`]: per-pixel colour of each [`Mode`] but `h`.
//! - [`edges`]: the `h` picture's edges, coloured by their resolved h.
//! - [`mod@sheet`]: several documents side by side, one row per mode, one group per view, and PNG.
//!
//! Pictures are byte-identical at any thread count: each band of rows is filled by one thread
//! in triangle order, and shading reads only its own pixel.

pub mod camera;
pub mod edges;
pub mod raster;
pub mod scene;
pub mod shade;
pub mod sheet;

pub use camera::{Camera, View};
pub use edges::{EdgeClass, MeshEdges};
pub use scene::Scene;
pub use sheet::{sheet, sheet_size, Image, Mode, Settings, Subject, MAX_PIXELS};
