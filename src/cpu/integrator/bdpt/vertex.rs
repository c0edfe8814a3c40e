//! The vertices of bidirectional path tracing's subpaths, and the densities its MIS weights
//! compare (WGSL side: `shaders/integrator/bdpt/vertex.wgsl`). Every density is per unit area
//! at the vertex it leads to, or per unit solid angle where that vertex is at infinity, as in
//! Veach's thesis and pbrt's `BDPTIntegrator`.

use crate::cpu::core::camera::camera_direction_pdf;
use crate::cpu::core::frame::PI;
use crate::cpu::geometry::hit::Hit;
use crate::cpu::lights::emission::{
    area_origin_pdf, disk_pdf, infinite_light_pdf, point_direction_pdf, EMITTER_AREA,
    EMITTER_DELTA_DIRECTION, EMITTER_INFINITE, EMITTER_POINT,
};
use crate::cpu::materials::material::bsdf_pdf;
use crate::cpu::media::medium::MediumStack;
use crate::cpu::media::phase::hg_phase;
use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::{Material, PROJECTION_ORTHOGRAPHIC};
use glam::Vec3;

/// The camera end of a camera subpath (its lens point).
pub const VERTEX_CAMERA: u32 = 0;
/// A light's end of a light subpath, or where a camera subpath escapes to infinity.
pub const VERTEX_LIGHT: u32 = 1;
/// A surface a subpath met (an emitter among them: a camera subpath may end on one).
pub const VERTEX_SURFACE: u32 = 2;
/// A scattering event in a participating medium: its "BSDF" is the medium's phase function
/// (f = pdf = phase, no cosine anywhere: a point in a volume has no area).
pub const VERTEX_MEDIUM: u32 = 3;

#[derive(Clone, Copy, Debug)]
pub struct BdptVertex {
    /// `VERTEX_CAMERA`, `VERTEX_LIGHT`, `VERTEX_SURFACE` or `VERTEX_MEDIUM`.
    pub kind: u32,
    /// For light vertices: `EMITTER_AREA`, `EMITTER_POINT`, `EMITTER_INFINITE` or
    /// `EMITTER_DELTA_DIRECTION` (`src/cpu/lights/emission.rs`).
    pub emitter: u32,
    /// The surface point: position, error, geometric and shading normal facing the subpath's
    /// previous vertex, `front_face`, primitive, index. Camera and point-light vertices use the
    /// position alone.
    pub hit: Hit,
    /// The pbr coat's own shading normal, as the path tracer's `apply_normal_maps` gives it.
    pub coat_normal: Vec3,
    /// The material there (textures and vertex colours applied); surface vertices only.
    pub material: Material,
    /// Unit direction towards the previous vertex of the vertex's own subpath; at infinity,
    /// the direction the light travels (from the sky into the scene).
    pub dir: Vec3,
    /// The subpath's throughput up to this vertex.
    pub beta: Vec3,
    /// What a light vertex emits along `dir` (see `LightOrigin::emitted`).
    pub emitted: Vec3,
    /// The density with which the vertex's own subpath sampled it, and with which the other
    /// subpath's sampling would have produced it.
    pub pdf_fwd: f32,
    pub pdf_rev: f32,
    /// The vertex scattered by a delta lobe: no connection can end at it.
    pub delta: bool,
    /// The media the subpath's ray arriving at the vertex was in (media/medium.rs); a
    /// connection leaving through the surface crosses it first.
    pub media: MediumStack,
    /// Medium vertices: the Henyey–Greenstein asymmetry of the medium there.
    pub g: f32,
}

impl BdptVertex {
    pub fn is_infinite(&self) -> bool {
        self.kind == VERTEX_LIGHT
            && (self.emitter == EMITTER_INFINITE || self.emitter == EMITTER_DELTA_DIRECTION)
    }

    /// Whether the vertex has an area (its density converts with the cosine there).
    pub fn is_on_surface(&self) -> bool {
        self.kind == VERTEX_SURFACE || (self.kind == VERTEX_LIGHT && self.emitter == EMITTER_AREA)
    }

    /// A surface or medium vertex: one that scatters, where connections can join.
    pub fn scatters(&self) -> bool {
        self.kind == VERTEX_SURFACE || self.kind == VERTEX_MEDIUM
    }

    /// A point or spot light, or a sun without a disk: nothing can hit it.
    pub fn is_delta_light(&self) -> bool {
        self.kind == VERTEX_LIGHT
            && (self.emitter == EMITTER_POINT || self.emitter == EMITTER_DELTA_DIRECTION)
    }
}

/// The unit direction from vertex `from` to vertex `to` (one of them may be at infinity).
pub fn direction_between(from: &BdptVertex, to: &BdptVertex) -> Vec3 {
    if to.is_infinite() {
        return -to.dir;
    }
    if from.is_infinite() {
        return from.dir;
    }
    (to.hit.position - from.hit.position).normalize()
}

/// A solid-angle density at `from` as a density at `to`: per unit area there (times the
/// cosine at `to`, over the squared distance), unchanged for a vertex at infinity.
pub fn to_area_density(pdf: f32, from: &BdptVertex, to: &BdptVertex) -> f32 {
    if to.is_infinite() {
        return pdf;
    }
    let w = to.hit.position - from.hit.position;
    let distance2 = w.dot(w);
    if distance2 <= 0.0 {
        return 0.0;
    }
    let mut pdf = pdf / distance2;
    if to.is_on_surface() {
        pdf *= to.hit.normal.dot(w).abs() / distance2.sqrt();
    }
    pdf
}

/// The shading frame of a surface vertex seen from the side of `w`: shading and coat normals
/// facing it, and whether that side is the outside (`bsdf_eval`'s conventions).
pub fn facing(v: &BdptVertex, w: Vec3) -> (Vec3, Vec3, bool) {
    if w.dot(v.hit.normal) >= 0.0 {
        return (v.hit.shading_normal, v.coat_normal, v.hit.front_face);
    }
    (-v.hit.shading_normal, -v.coat_normal, !v.hit.front_face)
}

/// The solid-angle density of BSDF sampling at surface vertex `v` producing `wi` for light
/// leaving along `wo` (either subpath samples its next direction so).
pub fn surface_pdf(v: &BdptVertex, wo: Vec3, wi: Vec3) -> f32 {
    let (n, coat_n, front_face) = facing(v, wo);
    bsdf_pdf(&v.material, wo, wi, n, coat_n, front_face)
}

/// The solid-angle density of either subpath's sampling at scattering vertex `v` (a surface's
/// BSDF, a medium's phase function) producing `wi` for light leaving along `wo`.
pub fn scatter_pdf(v: &BdptVertex, wo: Vec3, wi: Vec3) -> f32 {
    if v.kind == VERTEX_MEDIUM {
        // The phase function's cosine is between the travelled and the scattered direction.
        return hg_phase(v.g, -wo.dot(wi));
    }
    surface_pdf(v, wo, wi)
}

/// The density with which a light vertex `v` sends its light to `next`: what the light
/// subpath's first segment would have drawn.
pub fn light_direction_density(scene: &SceneRefs, v: &BdptVertex, next: &BdptVertex) -> f32 {
    if v.is_infinite() {
        // Parallel rays through the scene's disk: uniform in area across the beam.
        let mut pdf = disk_pdf(scene);
        if next.is_on_surface() {
            pdf *= v.dir.dot(next.hit.normal).abs();
        }
        return pdf;
    }
    let w = direction_between(v, next);
    let pdf_dir = if v.kind == VERTEX_LIGHT && v.emitter == EMITTER_POINT {
        point_direction_pdf(scene, v.hit.index, w)
    } else {
        // An area emitter (a light subpath's origin, or a surface a camera path ended on):
        // cosine-weighted on either side.
        v.hit.normal.dot(w).abs() / (2.0 * PI)
    };
    to_area_density(pdf_dir, v, next)
}

/// The density with which light paths start at the emitter vertex `v` (selection included):
/// per unit area for area emitters, per unit solid angle (every infinite light's together)
/// at infinity. 0 where no light path can start: a background light sampling does not know.
pub fn light_origin_density(scene: &SceneRefs, v: &BdptVertex) -> f32 {
    if v.is_infinite() {
        return infinite_light_pdf(scene, -v.dir);
    }
    area_origin_pdf(scene, v.hit.primitive, v.hit.index)
}

/// The density with which vertex `v`, reached from `prev` (ignored at the subpath's ends),
/// samples `next`: the camera's density, a light's emission density or the BSDF's, as a
/// density at `next`.
pub fn density_to(
    scene: &SceneRefs,
    v: &BdptVertex,
    prev: Option<&BdptVertex>,
    next: &BdptVertex,
) -> f32 {
    let params = scene.params;
    if v.kind == VERTEX_CAMERA {
        if params.projection == PROJECTION_ORTHOGRAPHIC {
            // Parallel rays from a film uniform in area (only a camera path's own first vertex
            // asks; light tracing cannot reach an orthographic camera).
            let mut pdf = 1.0 / crate::cpu::core::camera::film_area(params);
            if next.is_on_surface() {
                pdf *= Vec3::from(params.forward).dot(next.hit.normal).abs();
            }
            return pdf;
        }
        let w = direction_between(v, next);
        return to_area_density(camera_direction_pdf(params, w), v, next);
    }
    if v.kind == VERTEX_LIGHT {
        return light_direction_density(scene, v, next);
    }
    let Some(prev) = prev else {
        return 0.0;
    };
    let wo = direction_between(v, prev);
    let wi = direction_between(v, next);
    to_area_density(scatter_pdf(v, wo, wi), v, next)
}
