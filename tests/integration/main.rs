//! Every integration test, as one binary: the modules below each test one behaviour of the
//! library or of the `g2tess` binary, and the shared helpers (`support`, `corpus`, `hostile`,
//! `gltf_build`, `schemes_support`, `sharpness_support`) build meshes, files and runs for them.
//! One binary links once, which is most of the time `cargo test` takes on a fresh clone.

mod buildsys;
mod buildsys_bazel;
mod buildsys_cli;
mod buildsys_ninja;
mod cli_batch;
mod cli_exit_codes;
mod cli_invalid;
mod cli_lod;
mod cli_nets;
mod cli_watch;
mod corpus;
mod encode_output;
mod gltf_build;
mod hostile;
mod hostile_files;
mod hostile_geometry;
mod hostile_limits;
mod io_config;
mod io_fixtures;
mod io_mutations;
mod io_roundtrip;
mod pipeline_adaptive;
mod pipeline_fixtures;
mod pipeline_morph;
mod pipeline_sharpness;
mod render;
mod render_report;
mod report_warnings;
mod schemes_continuity;
mod schemes_creases;
mod schemes_lattice;
mod schemes_shape;
mod schemes_support;
mod schemes_typos;
mod sharpness_formats;
mod sharpness_resolve;
mod sharpness_support;
mod stream_output;
mod support;
mod surface_continuity;
mod surface_one_pass;
mod surface_pn;
mod surface_props;
mod surface_shape;
mod tessellate;
mod tessellate_adaptive;
mod threads;
