//! glint's integration tests, as one test crate: one build, one link and one process, so
//! the GPU context (and the kernel pipelines it caches) are made once for the whole suite
//! instead of once per file. Each module's `//!` doc says what it covers. Run one area with
//! `cargo test --test suite pbr::`, one test with its full path.
//!
//! The modules follow the data flow: scene file → validated scene → kernel arrays →
//! renderer (GPU kernel or CPU mirror) → image, then the programs around it.

mod common;

// Scene files, mesh files and their errors.
mod cli;
mod fuzz_scenes;
mod gltf_materials;
mod gltf_samples;
mod hardening_io;
mod hardening_numeric;
mod mesh;
mod mesh_errors;
mod model;
mod obj_materials;
mod scene_errors;
mod vertex_colors;

// Scene → kernel arrays: the layout contract, bindings and variants.
mod layout;
mod scene_binding;
mod texel_windows;

// Traversal: intersection, the closest-hit rule, instances, hardware ray queries.
mod closest_hit;
mod coincident_copies;
mod hardware_traversal;
mod instancing;
mod intersect;

// Materials and textures.
mod alpha;
mod clearcoat_normals;
mod normal_maps;
mod pbr;
mod rough_glass;
mod shading_normals;
mod textured_emitters;
mod textures;
mod transmission;

// Lights, the environment and the integrator's statistics.
mod adaptive;
mod batch_means;
mod bdpt;
mod bdpt_media;
mod chi2;
mod closed_form;
mod environment;
mod gpu_vs_cpu;
mod grid_media;
mod light_tree;
mod lights;
mod media;
mod sampling;
mod statistics;

// The render driver and images: AOVs, denoising, interrupts, shards, memory.
mod aov;
mod denoise;
mod gpu_memory;
mod interrupt;
mod shard;

// Around the renderer: the viewer, clusters, the docs.
mod deploy;
mod docs;
mod slurm;
mod viewer;
mod viewer_display;
