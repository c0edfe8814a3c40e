// What sampling a BSDF returns (mirror: src/cpu/materials/bsdf.rs).

struct BsdfSample {
    dir: vec3<f32>,
    // f * cos / pdf, or the reflectance of a delta lobe; zero when the path is absorbed.
    weight: vec3<f32>,
    // Solid-angle pdf of dir; 0 for delta lobes.
    pdf: f32,
    // Light sampling cannot find dir, so what the ray reaches counts in full: delta lobes,
    // smooth refraction among them (material.wgsl's transmits_roughly says which is rough).
    is_delta: bool,
}
