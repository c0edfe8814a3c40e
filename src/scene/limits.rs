//! The numeric range glint supports, checked when a scene is loaded (documented in README.md,
//! "Numeric range"). The kernel computes in f32: inside these bounds no product it forms
//! (squared distances and radii, areas, light pdfs, radiance times throughput, the variance's
//! sums of squares) overflows or underflows into an infinite, NaN or vanishing value. Outside
//! them a scene is refused with the bound in the message, instead of rendering a wrong image.

/// Largest magnitude of any coordinate or vector component (eye, target, centres, corners,
/// quad edges) and of any length: squared distances stay below 1e17, far from f32's 3.4e38.
pub const MAX_COORDINATE: f32 = 1e8;

/// Smallest sphere radius, quad edge length and focus distance: squared radii and quad areas
/// stay above 1e-16, and a light of that size seen from the far end of the range still has a
/// finite pdf (sin² of its cone ≥ 1e-32, above f32's smallest normal number, 1.2e-38).
pub const MIN_LENGTH: f32 = 1e-8;

/// Largest emitted radiance (`emission × strength`, per channel) and background. With the
/// widest `ior` range, a path's radiance stays below the accumulator's sample bound
/// (`crate::cpu::integrator::accumulate::MAX_SAMPLE`), so a valid scene never loses a sample to it.
pub const MAX_RADIANCE: f64 = 1e10;

/// Range of a dielectric's index of refraction: refraction scales radiance by η², at most 1e4.
pub const MIN_IOR: f32 = 0.01;
pub const MAX_IOR: f32 = 100.0;

/// Largest magnitude of a normal map's `scale` (glTF allows any finite number): the scaled
/// tangent-space xy stays within f32's range after squaring.
pub const MAX_NORMAL_SCALE: f64 = 1e6;

/// Smallest sine of the angle between the camera's `up` and its view direction, and between
/// a quad's two edges: below it the basis (or the quad's normal) is not well defined in f32.
pub const MIN_SINE: f64 = 1e-6;
