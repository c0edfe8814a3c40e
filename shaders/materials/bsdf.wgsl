// What sampling a BSDF returns (mirror: src/cpu/materials/bsdf.rs).

struct BsdfSample {
    dir: vec3<f32>,
    // f * cos / pdf, or the reflectance of a delta lobe; zero when the path is absorbed.
    weight: vec3<f32>,
    // Solid-angle pdf of dir; 0 for delta lobes.
    pdf: f32,
    // Light sampling cannot find dir, so what the ray reaches counts in full: delta lobes, and
    // refraction (shadow rays do not pass through surfaces).
    is_delta: bool,
}
