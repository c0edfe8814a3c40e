//! Joining a light subpath's first s vertices to a camera subpath's first t (WGSL side:
//! `shaders/integrator/bdpt/connect.wgsl`), and the power-heuristic weight of that strategy
//! against every other (s', t') that could have made the same path (Veach 1997, §10.2; the
//! ratio form of pbrt's `MISWeight`).
//!
//! Strategies: s = 0, the camera subpath found an emitter (or the sky); s = 1, a camera vertex
//! joined to the light's own vertex (next-event estimation from the light subpath's origin);
//! t = 1, a light vertex seen through the camera, splatted into whatever pixel it lands in
//! (light tracing); every other (s, t) joins two surface vertices. t = 0 (a light path that
//! hits the lens) is not a strategy here: the lens cannot be hit.

use crate::cpu::core::camera::{camera_view, CameraView};
use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::{stream_id, Rng, PURPOSE_LIGHT};
use crate::cpu::geometry::hit::Hit;
use crate::cpu::geometry::hit::{hit_sphere, NO_HIT};
use crate::cpu::geometry::intersect::{escapes, unoccluded_before};
use crate::cpu::geometry::surface::offset_ray_origin;
use crate::cpu::geometry::triangle::{triangle_normal, triangle_plane_distance};
use crate::cpu::integrator::bdpt::vertex::{
    density_to, direction_between, light_direction_density, light_origin_density, BdptVertex,
    VERTEX_CAMERA, VERTEX_LIGHT, VERTEX_SURFACE,
};
use crate::cpu::integrator::bdpt::walk::{
    adjoint_f_cos, blank_vertex, radiance_f_cos, SampleId, CONNECTION_SEGMENTS, LIGHT_SUBPATH,
};
use crate::cpu::lights::emission::{
    area_origin_pdf, infinite_light_pdf, infinite_light_radiance, EMITTER_AREA,
    EMITTER_DELTA_DIRECTION, EMITTER_INFINITE, EMITTER_POINT,
};
use crate::cpu::lights::sampling::{light_visible, sample_light, sphere_chord, sphere_contains};
use crate::cpu::media::medium::{
    medium_crossed, medium_start, shadow_transmittance, transmittance_along, MediumStack,
    TrackingStream,
};
use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::{
    Params, LIGHT_SUN, PRIMITIVE_ENVIRONMENT, PRIMITIVE_LIGHT, PRIMITIVE_QUAD, PRIMITIVE_TRIANGLE,
    PROJECTION_ORTHOGRAPHIC,
};
use glam::Vec3;

/// What one strategy adds: radiance for the pixel being rendered, or (t = 1) for the pixel
/// `view` lands in.
#[derive(Clone, Copy, Debug)]
pub struct Connection {
    pub radiance: Vec3,
    /// t = 1 only: where the light vertex is seen.
    pub view: Option<CameraView>,
}

const NOTHING: Connection = Connection {
    radiance: Vec3::ZERO,
    view: None,
};

/// Whether nothing blocks the segment between two vertices (one may be at infinity): a
/// shadow ray from just off the first towards just off the second.
pub fn segment_clear(
    scene: &SceneRefs,
    a: &BdptVertex,
    b: &BdptVertex,
    id: SampleId,
    s: u32,
    t: u32,
) -> bool {
    let scene = keyed_connection(scene, id, s, t);
    let geometry = &scene.geometry;
    let join = join_ray(a, b, direction_between(a, b));
    if b.is_infinite() {
        return escapes(geometry, &join.ray);
    }
    if join.distance <= 0.0 {
        return false;
    }
    // Short of the far end by a sliver, as pbrt's `SpawnRayTo`: where a surface's point is
    // exact along its normal (an axis-aligned quad), its error bound and so its offset are 0,
    // and whether the ray meets that surface just before or just after `distance` is down to
    // rounding (measured: 4.5% of the joins from a wall to the floor were lost so).
    unoccluded_before(geometry, &join.ray, join.distance * (1.0 - SHADOW_EPSILON))
}

/// A join's shadow ray, from just off vertex `a` along `dir` (`direction_between(a, b)`):
/// towards infinity where `b` is there, else towards `end_point`, just off `b`, `distance`
/// away (0 where the two points meet: no join).
struct JoinRay {
    ray: Ray,
    end_point: Vec3,
    distance: f32,
}

fn join_ray(a: &BdptVertex, b: &BdptVertex, dir: Vec3) -> JoinRay {
    let start = off_surface(a, dir);
    if b.is_infinite() {
        return JoinRay {
            ray: Ray { origin: start, dir },
            end_point: start,
            distance: 0.0,
        };
    }
    let end_point = off_surface(b, -dir);
    let to_end = end_point - start;
    let distance = to_end.length();
    JoinRay {
        ray: Ray {
            origin: start,
            dir: to_end / distance,
        },
        end_point,
        distance,
    }
}

/// The fraction of the light that gets from camera-side vertex `a` to vertex `b` (one may be
/// at infinity): 0 or 1 without media (`segment_clear`); with media, the transmittance along
/// the join, ratio-tracked through grid media as the path tracer's shadow rays are, crossing
/// interfaces with the medium stack following them. It starts from `a`, whose stack is the
/// camera subpath's own (so right even where a light subpath's assumed start medium is not).
pub fn segment_through(
    scene: &SceneRefs,
    a: &BdptVertex,
    b: &BdptVertex,
    id: SampleId,
    s: u32,
    t: u32,
) -> Vec3 {
    if scene.params.medium_count == 0 {
        return if segment_clear(scene, a, b, id, s, t) {
            Vec3::ONE
        } else {
            Vec3::ZERO
        };
    }
    let scene = keyed_connection(scene, id, s, t);
    let dir = direction_between(a, b);
    let join = join_ray(a, b, dir);
    let media = stack_towards(scene.params, a, dir);
    let tracking = TrackingStream {
        pixel: id.pixel,
        sample: id.sample,
        bounce: CONNECTION_TRACKING + s * 32 + t,
    };
    let mut unused = 0;
    if b.is_infinite() {
        let end = |_: &Ray, hit: &Hit| if hit.t == NO_HIT { NO_HIT } else { -1.0 };
        return transmittance_along(&scene, &join.ray, &media, &mut unused, tracking, end);
    }
    if join.distance <= 0.0 {
        return Vec3::ZERO;
    }
    let (end_point, distance) = (join.end_point, join.distance);
    // As `segment_clear`: short of the far end by a sliver of the join's length.
    let end = |piece: &Ray, hit: &Hit| {
        let t_end = (end_point - piece.origin).dot(piece.dir).max(0.0);
        if hit.t >= t_end - distance * SHADOW_EPSILON {
            t_end
        } else {
            -1.0
        }
    };
    transmittance_along(&scene, &join.ray, &media, &mut unused, tracking, end)
}

/// The media a ray from vertex `v` along `dir` starts in: the vertex's, crossed into the
/// medium its surface bounds where `dir` goes through it.
fn stack_towards(params: &Params, v: &BdptVertex, dir: Vec3) -> MediumStack {
    if v.kind == VERTEX_SURFACE && dir.dot(v.hit.normal) < 0.0 {
        return medium_crossed(params, &v.media, v.hit.material, v.hit.front_face);
    }
    v.media
}

/// The first "bounce" of connections' ratio-tracking streams: above both subpaths'.
pub const CONNECTION_TRACKING: u32 = 1 << 17;

/// The fraction of a join's length left unsearched at its far end (pbrt's `ShadowEpsilon`).
pub const SHADOW_EPSILON: f32 = 1e-4;

/// A vertex's point moved off its surface towards `dir` (points without a surface as they
/// are).
fn off_surface(v: &BdptVertex, dir: Vec3) -> Vec3 {
    if !v.is_on_surface() {
        return v.hit.position;
    }
    let side = if dir.dot(v.hit.normal) >= 0.0 {
        v.hit.normal
    } else {
        -v.hit.normal
    };
    offset_ray_origin(v.hit.position, v.hit.error, side)
}

/// s = 1's light point, drawn by next-event estimation's own sampler at camera vertex `pt`
/// (cones for spheres, the map by luminance; the path tracer's stream for that bounce), as
/// pbrt's bidirectional integrator resamples it: far better for direct light than the light
/// subpath's first vertex, uniform on the emitter. Returns the light vertex, with the density
/// a light path would start there with (the MIS weights compare strategies by that), and the
/// unweighted contribution; `None` where nothing arrives.
fn direct_light(
    scene: &SceneRefs,
    pt: &BdptVertex,
    t: usize,
    id: SampleId,
) -> Option<(BdptVertex, Vec3)> {
    let params = scene.params;
    let mut rng = Rng::with_sampler(
        id.pixel,
        id.sample,
        stream_id(t as u32 - 2, PURPOSE_LIGHT),
        params.seed,
        params.sampler,
    );
    let probe = off_surface(pt, pt.dir);
    let light = sample_light(scene, pt.hit.position, probe, &mut rng);
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(light.pdf > 0.0) {
        return None;
    }
    let f = radiance_f_cos(pt, pt.dir, light.dir);
    if f == Vec3::ZERO {
        return None;
    }
    let mut v = blank_vertex();
    v.kind = VERTEX_LIGHT;
    let p = pt.hit.position;
    if light.primitive == PRIMITIVE_LIGHT {
        let l = &scene.lights[light.index as usize];
        v.hit.index = light.index;
        if l.kind == LIGHT_SUN {
            v.dir = -light.dir;
            if l.sun_one_minus_cos > 0.0 {
                v.emitter = EMITTER_INFINITE;
                v.pdf_fwd = infinite_light_pdf(scene, light.dir);
            } else {
                v.emitter = EMITTER_DELTA_DIRECTION;
                v.pdf_fwd = l.light_probability;
            }
        } else {
            v.emitter = EMITTER_POINT;
            v.hit.position = Vec3::from(l.position);
            v.pdf_fwd = l.light_probability;
        }
    } else if light.primitive == PRIMITIVE_ENVIRONMENT {
        v.emitter = EMITTER_INFINITE;
        v.dir = -light.dir;
        v.pdf_fwd = infinite_light_pdf(scene, light.dir);
    } else {
        // The point the direction meets on the emitter, and its normal, facing pt.
        let (distance, normal) =
            emitter_point(scene, light.primitive, light.index, p, probe, light.dir)?;
        v.emitter = EMITTER_AREA;
        v.hit.position = p + distance * light.dir;
        v.hit.normal = if normal.dot(light.dir) < 0.0 {
            normal
        } else {
            -normal
        };
        v.hit.primitive = light.primitive;
        v.hit.index = light.index;
        v.pdf_fwd = area_origin_pdf(scene, light.primitive, light.index);
    }
    let shadow_scene = keyed_connection(scene, id, 1, t as u32);
    let origin = off_surface(pt, light.dir);
    let shadow = Ray {
        origin,
        dir: light.dir,
    };
    let mut through = Vec3::ONE;
    if params.medium_count > 0 {
        // Through the media as the path tracer's next-event estimation sees them.
        let media = stack_towards(params, pt, light.dir);
        let tracking = TrackingStream {
            pixel: id.pixel,
            sample: id.sample,
            bounce: CONNECTION_TRACKING + 32 + t as u32,
        };
        let mut unused = 0;
        through = shadow_transmittance(
            &shadow_scene,
            &shadow,
            &light,
            &media,
            &mut unused,
            tracking,
        );
        if through == Vec3::ZERO {
            return None;
        }
    } else if !light_visible(&shadow_scene, &shadow, &light) {
        return None;
    }
    Some((v, pt.beta * f * through * light.radiance / light.pdf))
}

/// Where a ray from `p` along `dir` meets the area emitter (primitive, index): its distance and
/// the emitter's outward normal there.
fn emitter_point(
    scene: &SceneRefs,
    primitive: u32,
    index: u32,
    p: Vec3,
    probe: Vec3,
    dir: Vec3,
) -> Option<(f32, Vec3)> {
    let g = &scene.geometry;
    let (distance, normal) = if primitive == PRIMITIVE_TRIANGLE {
        let tri = &g.triangles[index as usize];
        let normal = triangle_normal(tri);
        (triangle_plane_distance(tri, normal, p, dir), normal)
    } else if primitive == PRIMITIVE_QUAD {
        let q = &g.quads[index as usize];
        let normal = Vec3::from(q.normal);
        ((q.plane_offset - normal.dot(p)) / normal.dot(dir), normal)
    } else {
        let s = &g.spheres[index as usize];
        // From inside (as light sampling decides it, by `probe`), the chord's far end: p
        // itself may lie on the sphere.
        let t = if sphere_contains(s, probe) {
            sphere_chord(s, p, dir).0
        } else {
            hit_sphere(s, &Ray { origin: p, dir })
        };
        if t == NO_HIT {
            return None;
        }
        (t, (p + t * dir - Vec3::from(s.center)) / s.radius)
    };
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(distance > 0.0 && distance.is_finite()) {
        return None;
    }
    Some((distance, normal))
}

/// The scene with the alpha decisions of the connection (s, t).
fn keyed_connection<'a>(scene: &SceneRefs<'a>, id: SampleId, s: u32, t: u32) -> SceneRefs<'a> {
    if scene.has_alpha() {
        let key = crate::cpu::geometry::alpha::alpha_segment_key(
            scene.params,
            id.pixel,
            id.sample,
            CONNECTION_SEGMENTS + s * 32 + t,
        );
        return scene.with_alpha_key(key);
    }
    *scene
}

/// The radiance strategy (s, t) adds, unweighted; t = 1 also says where it lands. `lens` is
/// t = 1's lens sample.
fn unweighted(
    scene: &SceneRefs,
    light: &[BdptVertex],
    camera: &[BdptVertex],
    s: usize,
    t: usize,
    id: SampleId,
    camera_vertex: &mut BdptVertex,
) -> Connection {
    let params = scene.params;
    if s == 0 {
        // The camera subpath ends on an emitter or in the sky.
        let pt = &camera[t - 1];
        if pt.kind == VERTEX_LIGHT {
            return Connection {
                radiance: pt.beta * infinite_light_radiance(scene, -pt.dir),
                view: None,
            };
        }
        let emission = Vec3::from(pt.material.emission);
        return Connection {
            radiance: pt.beta * emission,
            view: None,
        };
    }
    let qs = &light[s - 1];
    if t == 1 {
        // Light tracing: the light vertex seen through the lens.
        if qs.delta || params.projection == PROJECTION_ORTHOGRAPHIC || !qs.scatters() {
            return NOTHING;
        }
        let mut lens_rng = Rng::with_sampler(
            id.pixel,
            id.sample,
            stream_id(LIGHT_SUBPATH + s as u32, PURPOSE_LIGHT),
            params.seed,
            params.sampler,
        );
        let lens = (lens_rng.next_f32(), lens_rng.next_f32());
        let view = camera_view(params, qs.hit.position, lens);
        if !view.visible {
            return NOTHING;
        }
        *camera_vertex = blank_vertex();
        camera_vertex.kind = VERTEX_CAMERA;
        camera_vertex.hit.position = view.lens_point;
        camera_vertex.beta = Vec3::ONE;
        camera_vertex.media = medium_start(params);
        let to_camera = -view.dir;
        let f_cos = adjoint_f_cos(qs, qs.dir, to_camera);
        if f_cos == Vec3::ZERO {
            return NOTHING;
        }
        // W_e over the lens point's density, times the geometry term, with |cos| at the vertex
        // in f_cos: 1 / (A cos³θ d²), the same for a pinhole and a thin lens.
        let importance = view.pdf_direction / (view.distance * view.distance);
        let through = segment_through(scene, camera_vertex, qs, id, s as u32, 1);
        if through == Vec3::ZERO {
            return NOTHING;
        }
        return Connection {
            radiance: qs.beta * f_cos * importance * through,
            view: Some(view),
        };
    }
    let pt = &camera[t - 1];
    if !pt.scatters() || pt.delta {
        return NOTHING;
    }
    let to_light = direction_between(pt, qs);
    let f_pt = radiance_f_cos(pt, pt.dir, to_light);
    if f_pt == Vec3::ZERO {
        return NOTHING;
    }
    // s ≥ 2 (s = 1 is next-event estimation's, in `connect`).
    if qs.delta || !qs.scatters() {
        return NOTHING;
    }
    let f_qs = adjoint_f_cos(qs, qs.dir, -to_light);
    let d = qs.hit.position - pt.hit.position;
    let radiance = qs.beta * f_qs * f_pt * pt.beta / d.dot(d);
    if radiance == Vec3::ZERO {
        return NOTHING;
    }
    let through = segment_through(scene, pt, qs, id, s as u32, t as u32);
    Connection {
        radiance: radiance * through,
        view: None,
    }
}

/// Delta densities are stored as 0 and cancel in the ratios (pbrt's `remap0`).
fn remap0(pdf: f32) -> f32 {
    if pdf != 0.0 {
        pdf
    } else {
        1.0
    }
}

/// The power-heuristic weight of strategy (s, t) for the path it made, against every other
/// strategy that could have made it. `camera_vertex` is t = 1's lens vertex.
///
/// In participating media the densities compared leave out distance sampling, as pbrt-v3's
/// BDPT does: every strategy samples each segment's free flight (or the transmittance along
/// a join, which has no density) with the same factors, so leaving them out of every
/// strategy's density alike keeps the weights summing to 1 for every path, and the densities
/// stay scalar in chromatic media (one-sample spectral MIS would need a channel-mixture
/// density per segment instead). Medium vertices contribute their phase function's density,
/// converted to area measure without a cosine (`to_area_density`). Only the variance pays:
/// a join through dense fog is weighted as if it were clear.
fn mis_weight(
    scene: &SceneRefs,
    light: &[BdptVertex],
    camera: &[BdptVertex],
    s: usize,
    t: usize,
    camera_vertex: &BdptVertex,
) -> f32 {
    if s + t == 2 {
        return 1.0;
    }
    let cam = |i: usize| -> &BdptVertex {
        if t == 1 && i == 0 {
            camera_vertex
        } else {
            &camera[i]
        }
    };
    let pt = cam(t - 1);
    // The densities the connection changes: of the two joined vertices and their
    // predecessors, each as the other subpath would have sampled it.
    let pt_rev;
    let mut pt_minus_rev = 0.0;
    let mut qs_rev = 0.0;
    let mut qs_minus_rev = 0.0;
    if s > 0 {
        let qs = &light[s - 1];
        let qs_minus = if s > 1 { Some(&light[s - 2]) } else { None };
        pt_rev = density_to(scene, qs, qs_minus, pt);
        let pt_minus = if t > 1 { Some(cam(t - 2)) } else { None };
        qs_rev = density_to(scene, pt, pt_minus, qs);
        if let Some(pm) = pt_minus {
            pt_minus_rev = density_to(scene, pt, Some(qs), pm);
        }
        if let Some(qm) = qs_minus {
            qs_minus_rev = density_to(scene, qs, Some(pt), qm);
        }
    } else {
        // The camera subpath's end is an emitter: how a light path would have started there.
        let origin = light_origin_density(scene, pt);
        if origin <= 0.0 {
            // No light path starts on it (a background light sampling does not know): only
            // the camera could have found it.
            return 1.0;
        }
        pt_rev = origin;
        if t > 1 {
            let mut as_light = *pt;
            if pt.kind == VERTEX_SURFACE {
                as_light.kind = VERTEX_LIGHT;
                as_light.emitter = EMITTER_AREA;
            }
            pt_minus_rev = light_direction_density(scene, &as_light, cam(t - 2));
        }
    }
    let mut sum = 0.0f32;
    // Camera side: strategies with fewer camera vertices.
    let mut ratio = 1.0f32;
    for i in (1..t).rev() {
        let rev = if i == t - 1 {
            pt_rev
        } else if i + 2 == t {
            pt_minus_rev
        } else {
            cam(i).pdf_rev
        };
        ratio *= remap0(rev) / remap0(cam(i).pdf_fwd);
        let delta_here = i != t - 1 && cam(i).delta;
        if !delta_here && !cam(i - 1).delta {
            sum += ratio * ratio;
        }
    }
    // Light side: strategies with fewer light vertices.
    let mut ratio = 1.0f32;
    for i in (0..s).rev() {
        let rev = if i == s - 1 {
            qs_rev
        } else if i + 2 == s {
            qs_minus_rev
        } else {
            light[i].pdf_rev
        };
        ratio *= remap0(rev) / remap0(light[i].pdf_fwd);
        let delta_here = i != s - 1 && light[i].delta;
        let delta_before = if i > 0 {
            light[i - 1].delta
        } else {
            light[0].is_delta_light()
        };
        if !delta_here && !delta_before {
            sum += ratio * ratio;
        }
    }
    let weight = 1.0 / (1.0 + sum);
    if weight.is_finite() {
        weight
    } else {
        0.0
    }
}

/// Strategy (s, t)'s contribution, weighted unless `weighted` is false (for tests of the
/// strategies one by one).
pub fn connect(
    scene: &SceneRefs,
    light: &[BdptVertex],
    camera: &[BdptVertex],
    s: usize,
    t: usize,
    id: SampleId,
    weighted: bool,
) -> Connection {
    let mut camera_vertex = camera[0];
    if s == 1 {
        let pt = &camera[t - 1];
        if !pt.scatters() || pt.delta {
            return NOTHING;
        }
        let Some((light_vertex, radiance)) = direct_light(scene, pt, t, id) else {
            return NOTHING;
        };
        let weight = if weighted {
            mis_weight(scene, &[light_vertex], camera, 1, t, &camera_vertex)
        } else {
            1.0
        };
        return Connection {
            radiance: radiance * weight,
            view: None,
        };
    }
    let c = unweighted(scene, light, camera, s, t, id, &mut camera_vertex);
    if c.radiance == Vec3::ZERO {
        return NOTHING;
    }
    let weight = if weighted {
        mis_weight(scene, light, camera, s, t, &camera_vertex)
    } else {
        1.0
    };
    Connection {
        radiance: c.radiance * weight,
        view: c.view,
    }
}
