//! glTF in and out: reads `.gltf`/`.glb` into a [`Document`] that keeps everything, exposes its
//! triangle primitives as plain arrays, and writes the document back with replaced primitives.
//!
//! The only module that speaks glTF. It deliberately does no geometry: the pipeline reads a
//! [`PrimitiveData`], computes a new one and hands it to [`replace_primitive`].
//!
//! - [`document`]: reading, [`Document`], [`ReadOptions`]
//! - [`glb`]: the GLB container
//! - [`uri`]: `data:` and file `uri`s, bounded to the asset's folder
//! - [`meshopt_decode`]: EXT_/KHR_meshopt_compression buffer views
//! - [`draco_decode`]: KHR_draco_mesh_compression primitives, decoded to plain arrays
//! - [`mod@quantize`]: KHR_mesh_quantization of every mesh ([`Quantization`])
//! - [`dequantize_nodes`]: the node transforms that undo position quantization, on write
//! - [`meshopt_encode`]: EXT_meshopt_compression of the written views ([`Compression`])
//! - [`accessor`]: every accessor layout, sparse and zero-filled ones
//! - [`validate`]: what the spec calls an error, refused at read time
//! - [`primitive`]: [`PrimitiveData`] out of and back into a document
//! - [`json_merge`]: keeps what the typed JSON model loses
//! - [`mod@write`]: `.glb` or `.gltf` + `.bin`, atomically, streamed from the buffers in memory
//! - [`stream`]: an output written (or compared with disk) while its document is being made
//! - `compare`: bytes compared with a file in chunks as they are produced (`--check`)
//! - [`lod`]: coarser levels of detail as new meshes and nodes linked by `MSFT_lod`
//! - `read_file`: a file's bytes read by every thread at once
//! - [`files`]: the files an asset reads and the files an output consists of, by name
//! - `bounds`: accessor `min`/`max`, in parallel
//! - `buffer_data`: buffers held in the element type they were made in, shared with the writer
//! - [`error`]: [`Error`], located by JSON path

pub mod accessor;
mod bounds;
mod buffer_data;
mod compare;
pub mod dequantize_nodes;
pub mod document;
pub mod draco_decode;
pub mod error;
pub mod files;
pub mod glb;
pub mod json_merge;
pub mod lod;
pub mod meshopt_decode;
pub mod meshopt_encode;
pub mod primitive;
pub mod quantize;
mod read_file;
pub mod stream;
pub mod uri;
pub mod validate;
pub mod write;

pub use document::{read, read_bytes, Document, ReadOptions};
pub use error::{Error, ErrorKind, Result};
pub use files::{fallback_path, output_files, referenced_files};
pub use meshopt_encode::Compression;
pub use primitive::{
    replace_primitive, replace_primitive_owned, semantic, Attribute, MorphDeltas, PrimitiveData,
    PrimitiveSize, Values,
};
pub use quantize::{quantize, Quantization};
pub use stream::{StreamMode, Streamed, StreamedOutput};
pub use write::{
    encode, to_glb_bytes, write, write_files_atomically, Files, OutputFile, WriteOptions,
};
