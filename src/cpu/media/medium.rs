//! Homogeneous media along a path (WGSL side: `shaders/media/medium.wgsl`).
//!
//! Which medium a ray is in follows the boundaries it crosses: a stack of medium slots
//! (`Params::media`), the global medium beneath them. Entering an object whose material bounds
//! a medium (through its front face) pushes that medium; leaving it (through a back face)
//! removes it, and the ray is back in whatever it was in before. Objects that bound no medium
//! change nothing: a glass ball in fog is full of fog. The stack holds [`MEDIUM_STACK_SIZE`]
//! media nested in one another; a deeper one is not entered (its inside takes the medium
//! around it).
//!
//! Free flights are sampled in closed form (homogeneous media: the majorant of delta tracking
//! is σt itself and no null collision happens), by one-sample spectral MIS over the three
//! channels: a channel picked uniformly, a distance from its exponential, and the estimate
//! divided by the mixture of the three channels' densities (the balance heuristic, Miller,
//! Georgiev and Jarosz 2019), so chromatic media are unbiased in every channel.

use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::{stream_id, Rng, PURPOSE_TRACKING};
use crate::cpu::geometry::hit::Hit;
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::geometry::intersect::intersect_scene;
use crate::cpu::geometry::surface::offset_ray_origin;
use crate::cpu::lights::light_sample::LightSample;
use crate::cpu::media::grid::{grid_free_flight, grid_transmittance};
use crate::cpu::scene_refs::SceneRefs;
use crate::kernel::types::{
    Material, Medium, Params, LIGHT_SUN, MATERIAL_DIELECTRIC, NO_GRID, NO_MEDIUM,
    PRIMITIVE_ENVIRONMENT, PRIMITIVE_LIGHT,
};
use glam::Vec3;

/// Media nested in one another that a path can be in at once (the global one aside).
pub const MEDIUM_STACK_SIZE: usize = 4;

/// Interfaces a shadow ray crosses at most on its way to a light; a light behind more is
/// taken as blocked. Each crossing is one more ray cast (lavapipe's loop budget counts them:
/// `src/gpu/loop_budget.rs`).
pub const MAX_SHADOW_CROSSINGS: u32 = 8;

/// Segments a path or subpath of at most `max_vertices` vertices (the camera's included) traces
/// at most: its scattering events' and, between them, interfaces crossed, which `max_bounces`
/// does not count. Bounds a path caught between interfaces.
pub fn segment_limit(max_vertices: u32) -> u32 {
    4 * max_vertices + 8
}

/// The media a path is in: `slots[..depth]`, innermost last.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MediumStack {
    pub slots: [u32; MEDIUM_STACK_SIZE],
    pub depth: u32,
}

/// Where a camera ray starts: the global medium, and the camera's own inside it if it has one.
pub fn medium_start(params: &Params) -> MediumStack {
    let mut stack = MediumStack::default();
    if params.camera_medium < params.medium_count {
        stack.slots[0] = params.camera_medium;
        stack.depth = 1;
    }
    stack
}

/// The slot of the medium the path is in, or [`NO_MEDIUM`].
pub fn current_medium(params: &Params, stack: &MediumStack) -> u32 {
    if stack.depth > 0 {
        return stack.slots[stack.depth as usize - 1];
    }
    if params.global_medium < params.medium_count {
        return params.global_medium;
    }
    NO_MEDIUM
}

/// The slot of the medium objects of `material` bound, or [`NO_MEDIUM`].
pub fn boundary_slot(params: &Params, material: u32) -> u32 {
    for i in 0..params.medium_count.min(params.media.len() as u32) {
        if params.media[i as usize].boundary == material {
            return i;
        }
    }
    NO_MEDIUM
}

/// The stack after crossing a surface of `material`, into the object through its front face
/// or out of it through a back face.
pub fn medium_crossed(
    params: &Params,
    stack: &MediumStack,
    material: u32,
    front_face: bool,
) -> MediumStack {
    let mut out = *stack;
    let slot = boundary_slot(params, material);
    if slot == NO_MEDIUM {
        return out;
    }
    if front_face {
        if (out.depth as usize) < MEDIUM_STACK_SIZE {
            out.slots[out.depth as usize] = slot;
            out.depth += 1;
        }
        return out;
    }
    // The innermost entry of this medium goes; those inside it (overlapping objects left in
    // another order than entered) move down.
    let mut found = false;
    for i in (0..out.depth as usize).rev() {
        if !found && out.slots[i] == slot {
            found = true;
            for j in i..MEDIUM_STACK_SIZE - 1 {
                out.slots[j] = out.slots[j + 1];
            }
        }
    }
    if found {
        out.depth -= 1;
    }
    out
}

/// Surfaces [`media_around`] passes at most on its way out of the scene.
pub const MAX_SURROUNDING_SURFACES: u32 = 16;

/// The direction [`media_around`] looks along: any fixed one, skewed off the axes so that it
/// does not graze axis-aligned walls.
const SURROUNDINGS_DIRECTION: Vec3 = Vec3::new(0.267_261_24, 0.801_783_7, 0.534_522_5);

/// The media whose objects enclose point `p` (a lamp inside a fogged box), innermost last: a
/// ray from `p` out of the scene, through every surface, leaves each of them through a back
/// face that it did not enter on the way. Up to [`MAX_SURROUNDING_SURFACES`] surfaces and
/// [`MEDIUM_STACK_SIZE`] media; without a camera-like declaration, this is how a light
/// subpath learns the medium it starts in.
pub fn media_around(scene: &SceneRefs, p: Vec3) -> MediumStack {
    let params = scene.params;
    // Slots of media that objects bound come first: without one, nothing encloses `p` (a
    // global fog), and the walk's rays are spared.
    if params.medium_count == 0 || params.media[0].boundary == NO_MEDIUM {
        return MediumStack::default();
    }
    let mut ray = Ray {
        origin: p,
        dir: SURROUNDINGS_DIRECTION,
    };
    // Media entered on the way out (objects beside `p`, not around it), and those left.
    let mut entered = MediumStack::default();
    let mut around = MediumStack::default();
    for _ in 0..MAX_SURROUNDING_SURFACES {
        let hit = intersect_scene(&scene.geometry, &ray);
        if hit.t == NO_HIT {
            break;
        }
        let slot = boundary_slot(params, hit.material);
        if slot != NO_MEDIUM {
            if hit.front_face {
                entered = medium_crossed(params, &entered, hit.material, true);
            } else if entered.slots[..entered.depth as usize].contains(&slot) {
                entered = medium_crossed(params, &entered, hit.material, false);
            } else if (around.depth as usize) < MEDIUM_STACK_SIZE {
                around.slots[around.depth as usize] = slot;
                around.depth += 1;
            }
        }
        ray.origin = offset_ray_origin(hit.position, hit.error, -hit.normal);
    }
    // Found innermost first; the stack holds the outermost first.
    around.slots[..around.depth as usize].reverse();
    around
}

/// An index-matched, untinted dielectric (`type = "interface"`): it only separates media, so
/// paths and shadow rays cross it without scattering.
pub fn is_interface(m: &Material) -> bool {
    m.kind == MATERIAL_DIELECTRIC && m.ior == 1.0 && m.albedo == [1.0; 3]
}

/// exp(−σt d) per channel; 1 where σt is 0 (also over an infinite d).
pub fn transmittance(sigma_t: Vec3, d: f32) -> Vec3 {
    let channel = |s: f32| if s > 0.0 { (-(s * d)).exp() } else { 1.0 };
    Vec3::new(channel(sigma_t.x), channel(sigma_t.y), channel(sigma_t.z))
}

/// Where a shadow ray's ratio tracking draws from: the stream `PURPOSE_TRACKING` of the
/// vertex at `bounce` of the path of (`pixel`, `sample`).
#[derive(Clone, Copy, Debug)]
pub struct TrackingStream {
    pub pixel: u32,
    pub sample: u32,
    pub bounce: u32,
}

/// The transmittance of medium slot `slot` ([`NO_MEDIUM`]: none) along `ray` from 0 to `t`:
/// Beer's law in a homogeneous medium, ratio tracking in a grid medium (from `rng`, made from
/// `tracking` when first needed).
pub fn segment_transmittance(
    scene: &SceneRefs,
    slot: u32,
    ray: &Ray,
    t: f32,
    tracking: TrackingStream,
    rng: &mut Option<Rng>,
) -> Vec3 {
    if slot == NO_MEDIUM {
        return Vec3::ONE;
    }
    let params = scene.params;
    let m = &params.media[slot as usize];
    if m.grid != NO_GRID {
        let rng = rng.get_or_insert_with(|| {
            let stream = stream_id(tracking.bounce, PURPOSE_TRACKING);
            Rng::with_sampler(
                tracking.pixel,
                tracking.sample,
                stream,
                params.seed,
                params.sampler,
            )
        });
        return grid_transmittance(scene.grids, m, ray, t, rng);
    }
    transmittance(Vec3::from(m.sigma_t), t)
}

/// A free flight: where it ended, and the factor the path's throughput takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeFlight {
    pub t: f32,
    pub weight: Vec3,
    /// True when it ended in the medium (a scattering event at `t`), false at the surface.
    pub scattered: bool,
}

/// Samples where light travelling through `m` towards a surface at `t_max` ([`NO_HIT`]: none)
/// first interacts, from two uniform numbers: the channel and the distance. A scattering event
/// at t is weighted σs Tr(t) / p(t) and reaching the surface Tr(t_max) / P(t_max), p and P
/// the three channels' densities and survival probabilities averaged.
pub fn sample_free_flight(m: &Medium, t_max: f32, u_channel: f32, u_distance: f32) -> FreeFlight {
    let sigma_t = Vec3::from(m.sigma_t);
    let channel = ((u_channel * 3.0) as usize).min(2);
    let s = sigma_t[channel];
    let mut t = NO_HIT;
    if s > 0.0 {
        t = -(1.0 - u_distance).ln() / s;
    }
    if t < t_max {
        let tr = transmittance(sigma_t, t);
        let pdf = (sigma_t * tr).dot(Vec3::splat(1.0 / 3.0));
        return FreeFlight {
            t,
            weight: Vec3::from(m.sigma_s) * tr / pdf,
            scattered: true,
        };
    }
    let tr = transmittance(sigma_t, t_max);
    let survival = tr.dot(Vec3::splat(1.0 / 3.0));
    let weight = if survival > 0.0 {
        tr / survival
    } else {
        Vec3::ZERO
    };
    FreeFlight {
        t: t_max,
        weight,
        scattered: false,
    }
}

/// A free flight through medium slot `slot` ([`NO_MEDIUM`]: none) along `ray` towards a
/// surface at `t_hit` (`NO_HIT`: none), from the flight's stream `rng`: delta tracking in a
/// grid medium, closed form in a homogeneous one. Shared by the path tracer and both of
/// bidirectional's subpaths.
pub fn sample_flight(
    scene: &SceneRefs,
    slot: u32,
    ray: &Ray,
    t_hit: f32,
    rng: &mut Rng,
) -> FreeFlight {
    if slot == NO_MEDIUM {
        return FreeFlight {
            t: t_hit,
            weight: Vec3::ONE,
            scattered: false,
        };
    }
    let m = &scene.params.media[slot as usize];
    if m.grid != NO_GRID {
        return grid_free_flight(scene.grids, m, ray, t_hit, rng);
    }
    let (u_channel, u_distance) = (rng.next_f32(), rng.next_f32());
    sample_free_flight(m, t_hit, u_channel, u_distance)
}

/// The transmittance from the shadow ray's origin (in the media of `stack`) to the sampled
/// light: Beer's law over each segment, through interfaces, which change the medium as a path
/// crossing them would; zero where anything else blocks it. `scene` carries the shadow ray's
/// alpha key. Counts the rays it casts in `segments`. Grid media's segments are ratio
/// tracked, drawing from the `tracking` vertex's `PURPOSE_TRACKING` stream (made at the first
/// grid segment: homogeneous media need no random numbers here).
pub fn shadow_transmittance(
    scene: &SceneRefs,
    shadow: &Ray,
    light: &LightSample,
    stack: &MediumStack,
    segments: &mut u32,
    tracking: TrackingStream,
) -> Vec3 {
    let end = |ray: &Ray, hit: &Hit| -> f32 {
        // How far the light is along this ray, if nothing before it blocks it.
        if light.primitive == PRIMITIVE_ENVIRONMENT {
            if hit.t == NO_HIT {
                return NO_HIT;
            }
        } else if light.primitive == PRIMITIVE_LIGHT {
            let l = &scene.lights[light.index as usize];
            if l.kind == LIGHT_SUN {
                if hit.t == NO_HIT {
                    return NO_HIT;
                }
            } else {
                let t = (Vec3::from(l.position) - ray.origin).dot(ray.dir);
                if hit.t >= t {
                    return t;
                }
            }
        } else if hit.t != NO_HIT && hit.primitive == light.primitive && hit.index == light.index {
            return hit.t;
        }
        -1.0
    };
    transmittance_along(scene, shadow, stack, segments, tracking, end)
}

/// The transmittance along `shadow` (from media `stack`) to wherever `end` says it ends:
/// given the ray of the current piece and its first hit, the distance of the end along it, or
/// a negative number where the hit comes first. Interfaces before the end are crossed (the
/// stack follows them, as a path's would), anything else blocks. Shared by next-event
/// estimation's shadow rays and bidirectional's connections.
pub fn transmittance_along(
    scene: &SceneRefs,
    shadow: &Ray,
    stack: &MediumStack,
    segments: &mut u32,
    tracking: TrackingStream,
    end: impl Fn(&Ray, &Hit) -> f32,
) -> Vec3 {
    let params = scene.params;
    let mut rng = None;
    let mut ray = *shadow;
    let mut media = *stack;
    let mut through = Vec3::ONE;
    for i in 0..MAX_SHADOW_CROSSINGS {
        if i > 0 {
            *segments += 1;
        }
        let hit = intersect_scene(&scene.geometry, &ray);
        let t_end = end(&ray, &hit);
        let slot = current_medium(params, &media);
        if t_end >= 0.0 {
            return through * segment_transmittance(scene, slot, &ray, t_end, tracking, &mut rng);
        }
        if hit.t == NO_HIT || !is_interface(&scene.materials[hit.material as usize]) {
            return Vec3::ZERO;
        }
        through *= segment_transmittance(scene, slot, &ray, hit.t, tracking, &mut rng);
        media = medium_crossed(params, &media, hit.material, hit.front_face);
        ray = Ray {
            origin: offset_ray_origin(hit.position, hit.error, -hit.normal),
            dir: ray.dir,
        };
    }
    Vec3::ZERO
}
