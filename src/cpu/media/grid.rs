//! Heterogeneous media from density grids (WGSL side: `shaders/media/grid.wgsl`, the same
//! arithmetic in the same order): trilinear density lookups, a DDA over the majorant blocks,
//! delta tracking for free flights and ratio tracking for shadow rays.
//!
//! A grid medium's extinction is σt(x) = d(x) σ̂t, d the grid's density and σ̂t the medium's
//! coefficients per unit density (the same for scattering). Along a ray the majorant
//! m(x) ≥ d(x) is piecewise constant: the largest density a lookup can return in the block
//! the point is in (`src/scene/grid.rs`). The DDA visits the blocks the ray crosses in order,
//! so empty blocks (m = 0) cost one step each and no collision.
//!
//! Free flights (delta tracking, with one-sample spectral MIS over the three channels as the
//! homogeneous closed form has): a channel c picked uniformly samples tentative collisions
//! with the majorant m σ̂t[c]; each is real with probability d/m, the same for every channel.
//! The chance of the collisions' sequence under channel j's sampling is
//! σ̂t[j]^k exp(−σ̂t[j] ∫m) times factors common to all channels, k the tentative
//! collisions; `r` tracks σ̂t[j]^k exp(−σ̂t[j] ∫m) up to a common factor (normalised so that
//! its largest channel is 1). A real collision at the k-th is weighted σ̂s r' / mean(σ̂t r'),
//! r' before its own factor σ̂t; reaching the segment's end r / mean(r): the balance
//! heuristic over the three channels' samplings, as Miller, Georgiev and Jarosz (2019) and
//! pbrt-v4's `r_u` do. For a grey medium every weight is the albedo or 1.
//!
//! Shadow rays (ratio tracking): tentative collisions with the grey majorant m max(σ̂t), each
//! multiplying the transmittance by 1 − d σ̂t / (m max(σ̂t)) per channel.
//!
//! A flight or shadow segment stops after [`MAX_TRACKING_STEPS`] steps (each a block crossed
//! or a tentative collision): a free flight is then absorbed and a shadow ray blocked, a bias
//! only in media whose majorant's optical depth along one segment nears that count (and on
//! lavapipe a bound on the kernel's loops: `src/gpu/loop_budget.rs`).

use crate::cpu::core::ray::Ray;
use crate::cpu::core::rng::Rng;
use crate::cpu::geometry::hit::NO_HIT;
use crate::cpu::media::medium::FreeFlight;
use crate::kernel::types::{GridMedium, Medium};
use glam::{IVec3, Vec3};

/// Steps one tracked segment takes at most (blocks crossed and tentative collisions).
pub const MAX_TRACKING_STEPS: u32 = 256;

/// The grids and their numbers (`KernelScene::grids`, `grid_voxels`).
#[derive(Clone, Copy, Debug)]
pub struct Grids<'a> {
    pub grids: &'a [GridMedium],
    pub voxels: &'a [f32],
}

fn row(r: [f32; 4], p: Vec3) -> f32 {
    r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3]
}

fn row_linear(r: [f32; 4], d: Vec3) -> f32 {
    r[0] * d.x + r[1] * d.y + r[2] * d.z
}

/// A scene point in the grid's continuous coordinates.
pub fn to_grid(g: &GridMedium, p: Vec3) -> Vec3 {
    Vec3::new(
        row(g.to_grid_x, p),
        row(g.to_grid_y, p),
        row(g.to_grid_z, p),
    )
}

/// A scene direction in the grid's coordinates (not unit: distances along the ray keep their
/// scene units).
pub fn dir_to_grid(g: &GridMedium, d: Vec3) -> Vec3 {
    Vec3::new(
        row_linear(g.to_grid_x, d),
        row_linear(g.to_grid_y, d),
        row_linear(g.to_grid_z, d),
    )
}

fn voxel(voxels: &[f32], g: &GridMedium, x: i32, y: i32, z: i32) -> f32 {
    let index = g.voxels + x as u32 + g.dims[0] * (y as u32 + g.dims[1] * z as u32);
    voxels[index as usize]
}

fn lerp(a: f32, b: f32, w: f32) -> f32 {
    a * (1.0 - w) + b * w
}

/// The density at continuous grid coordinates `p`: trilinear between the eight voxel centres
/// around it, indices clamped into the grid (whose outer voxels are zero).
pub fn density(voxels: &[f32], g: &GridMedium, p: Vec3) -> f32 {
    let dims = Vec3::new(g.dims[0] as f32, g.dims[1] as f32, g.dims[2] as f32);
    let q = (p - Vec3::splat(0.5)).clamp(Vec3::splat(-1.0), dims);
    let f = q.floor();
    let w = q - f;
    let hi = IVec3::new(g.dims[0] as i32, g.dims[1] as i32, g.dims[2] as i32) - IVec3::ONE;
    let i0 = IVec3::new(f.x as i32, f.y as i32, f.z as i32);
    let a = i0.clamp(IVec3::ZERO, hi);
    let b = (i0 + IVec3::ONE).clamp(IVec3::ZERO, hi);
    let v = |x: i32, y: i32, z: i32| voxel(voxels, g, x, y, z);
    let c00 = lerp(v(a.x, a.y, a.z), v(b.x, a.y, a.z), w.x);
    let c10 = lerp(v(a.x, b.y, a.z), v(b.x, b.y, a.z), w.x);
    let c01 = lerp(v(a.x, a.y, b.z), v(b.x, a.y, b.z), w.x);
    let c11 = lerp(v(a.x, b.y, b.z), v(b.x, b.y, b.z), w.x);
    lerp(lerp(c00, c10, w.y), lerp(c01, c11, w.y), w.z)
}

/// The part of the ray (o + t d in grid coordinates, t in [0, t_max]) inside the grid's box
/// [0, dims]: (t_enter, t_exit), empty when t_enter ≥ t_exit.
pub fn clip(g: &GridMedium, o: Vec3, d: Vec3, t_max: f32) -> (f32, f32) {
    let mut t0 = 0.0f32;
    let mut t1 = t_max;
    for a in 0..3 {
        let size = g.dims[a] as f32;
        if d[a] != 0.0 {
            let inv = 1.0 / d[a];
            let ta = -o[a] * inv;
            let tb = (size - o[a]) * inv;
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        } else if o[a] < 0.0 || o[a] > size {
            return (1.0, 0.0);
        }
    }
    (t0, t1)
}

/// A walk through the majorant blocks a ray crosses (Amanatides and Woo's DDA).
#[derive(Clone, Copy, Debug)]
pub struct BlockWalk {
    pub cell: IVec3,
    step: IVec3,
    /// Where the ray leaves the cell across each axis' next boundary.
    t_next: Vec3,
    t_delta: Vec3,
}

impl BlockWalk {
    /// The walk from `t` on (inside the grid's box).
    pub fn new(g: &GridMedium, o: Vec3, d: Vec3, t: f32) -> BlockWalk {
        let block = g.block as f32;
        let p = o + t * d;
        let top = IVec3::new(g.blocks[0] as i32, g.blocks[1] as i32, g.blocks[2] as i32);
        let cells = (p / block).floor();
        let cell =
            IVec3::new(cells.x as i32, cells.y as i32, cells.z as i32).clamp(IVec3::ZERO, top - 1);
        let mut walk = BlockWalk {
            cell,
            step: IVec3::ZERO,
            t_next: Vec3::splat(NO_HIT),
            t_delta: Vec3::splat(NO_HIT),
        };
        for a in 0..3 {
            if d[a] > 0.0 {
                walk.step[a] = 1;
                walk.t_next[a] = ((cell[a] + 1) as f32 * block - o[a]) / d[a];
                walk.t_delta[a] = block / d[a];
            } else if d[a] < 0.0 {
                walk.step[a] = -1;
                walk.t_next[a] = (cell[a] as f32 * block - o[a]) / d[a];
                walk.t_delta[a] = -block / d[a];
            }
        }
        walk
    }

    /// Where the ray leaves the current block.
    pub fn t_end(&self) -> f32 {
        self.t_next.x.min(self.t_next.y.min(self.t_next.z))
    }

    /// Into the next block; false when that is outside the grid.
    pub fn advance(&mut self, g: &GridMedium) -> bool {
        let t = self.t_next;
        let a = if t.x <= t.y && t.x <= t.z {
            0
        } else if t.y <= t.z {
            1
        } else {
            2
        };
        self.cell[a] += self.step[a];
        self.t_next[a] += self.t_delta[a];
        self.cell[a] >= 0 && self.cell[a] < g.blocks[a] as i32
    }
}

/// The majorant of the walk's current block.
pub fn majorant(voxels: &[f32], g: &GridMedium, cell: IVec3) -> f32 {
    let index =
        g.majorants + cell.x as u32 + g.blocks[0] * (cell.y as u32 + g.blocks[1] * cell.z as u32);
    voxels[index as usize]
}

/// `r` scaled so that its largest channel is 1 (unchanged where all are 0).
fn normalised(r: Vec3) -> Vec3 {
    let top = r.max_element();
    if top > 0.0 {
        r / top
    } else {
        r
    }
}

/// exp(−x) per channel.
fn decay(x: Vec3) -> Vec3 {
    Vec3::new((-x.x).exp(), (-x.y).exp(), (-x.z).exp())
}

/// What one step of a [`MajorantTracker`] met.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackStep {
    /// Crossed a block without a tentative collision: step again.
    Crossed,
    /// A tentative collision at `tracker.t`, with the block's majorant `tracker.majorant`.
    Collision,
    /// Reached the segment's end (or left the grid) without one.
    Exit,
    /// Took [`MAX_TRACKING_STEPS`] steps: the caller absorbs or blocks.
    Cut,
}

/// Tentative collisions along a ray through a grid, sampled against the majorant blocks the
/// ray crosses at `scale` per unit of majorant density: the walk both trackings share.
/// Each [`MajorantTracker::step`] is one block crossed or one collision (a loop iteration of
/// the kernel, `src/gpu/loop_budget.rs` counts them).
#[derive(Clone, Copy, Debug)]
pub struct MajorantTracker {
    walk: BlockWalk,
    /// Where the tracking is, in the grid's frame along the ray.
    pub t: f32,
    t_exit: f32,
    scale: f32,
    /// The exponential optical depth left to the next tentative collision.
    tau: f32,
    /// Whether `tau` is spent (a collision happened) and the next step draws a new one.
    draw_tau: bool,
    steps: u32,
    /// The majorant of the block of the last collision.
    pub majorant: f32,
    /// ∫ m dt since the caller last took it: the majorant's optical depth (per unit of the
    /// coefficients) swept since.
    pub swept: f32,
}

impl MajorantTracker {
    /// Tracking over [t_enter, t_exit] (inside the grid's box) of the grid-frame ray (o, d);
    /// draws the first exponential from `rng`.
    pub fn new(
        g: &GridMedium,
        o: Vec3,
        d: Vec3,
        span: (f32, f32),
        scale: f32,
        rng: &mut Rng,
    ) -> Self {
        MajorantTracker {
            walk: BlockWalk::new(g, o, d, span.0),
            t: span.0,
            t_exit: span.1,
            scale,
            tau: -(1.0 - rng.next_f32()).ln(),
            draw_tau: false,
            steps: 0,
            majorant: 0.0,
            swept: 0.0,
        }
    }

    /// The majorant optical depth swept since the last call.
    pub fn take_swept(&mut self) -> f32 {
        std::mem::take(&mut self.swept)
    }

    pub fn step(&mut self, grids: Grids, g: &GridMedium, rng: &mut Rng) -> TrackStep {
        if self.draw_tau {
            self.tau = -(1.0 - rng.next_f32()).ln();
            self.draw_tau = false;
        }
        if self.steps >= MAX_TRACKING_STEPS {
            return TrackStep::Cut;
        }
        self.steps += 1;
        let t = self.t;
        let end = self.walk.t_end().min(self.t_exit).max(t);
        let maj = majorant(grids.voxels, g, self.walk.cell);
        let rate = maj * self.scale;
        if rate > 0.0 && self.tau < rate * (end - t) {
            let tc = t + self.tau / rate;
            self.swept += maj * (tc - t);
            self.t = tc;
            self.majorant = maj;
            self.draw_tau = true;
            return TrackStep::Collision;
        }
        self.tau -= rate * (end - t);
        self.swept += maj * (end - t);
        self.t = end;
        if end >= self.t_exit || !self.walk.advance(g) {
            return TrackStep::Exit;
        }
        TrackStep::Crossed
    }
}

/// A free flight through grid medium `m` along `ray` towards a surface at `t_max`, by delta
/// tracking (the module's doc); `rng` is the flight's stream, whose first draw picks the
/// channel.
pub fn grid_free_flight(
    grids: Grids,
    m: &Medium,
    ray: &Ray,
    t_max: f32,
    rng: &mut Rng,
) -> FreeFlight {
    let g = &grids.grids[m.grid as usize];
    let sigma_t = Vec3::from(m.sigma_t);
    let sigma_s = Vec3::from(m.sigma_s);
    let u_channel = rng.next_f32();
    let channel = ((u_channel * 3.0) as usize).min(2);
    let lowest = sigma_t.min_element();
    let o = to_grid(g, ray.origin);
    let d = dir_to_grid(g, ray.dir);
    let (t_enter, t_exit) = clip(g, o, d, t_max);
    let absorbed = FreeFlight {
        t: t_max,
        weight: Vec3::ZERO,
        scattered: false,
    };
    let mut r = Vec3::ONE;
    if t_enter < t_exit {
        let mut tracker = MajorantTracker::new(g, o, d, (t_enter, t_exit), sigma_t[channel], rng);
        loop {
            let step = tracker.step(grids, g, rng);
            match step {
                TrackStep::Cut => return absorbed,
                TrackStep::Crossed => continue,
                TrackStep::Collision | TrackStep::Exit => {}
            }
            // Each channel's chance of no collision over the swept majorant, relative to the
            // lowest's (module doc).
            let swept = tracker.take_swept();
            r = normalised(r * decay((sigma_t - Vec3::splat(lowest)) * swept));
            if step == TrackStep::Exit {
                break;
            }
            let tc = tracker.t;
            let dens = density(grids.voxels, g, o + tc * d);
            if rng.next_f32() * tracker.majorant < dens {
                let pdf = (sigma_t * r).dot(Vec3::splat(1.0 / 3.0));
                if pdf > 0.0 {
                    return FreeFlight {
                        t: tc,
                        weight: sigma_s * r / pdf,
                        scattered: true,
                    };
                }
                return absorbed;
            }
            r = normalised(r * sigma_t);
        }
    }
    let survival = r.dot(Vec3::splat(1.0 / 3.0));
    if survival > 0.0 {
        return FreeFlight {
            t: t_max,
            weight: r / survival,
            scattered: false,
        };
    }
    absorbed
}

/// The transmittance of grid medium `m` along `ray` from 0 to `t_end`, by ratio tracking
/// (the module's doc), drawing from `rng`.
pub fn grid_transmittance(grids: Grids, m: &Medium, ray: &Ray, t_end: f32, rng: &mut Rng) -> Vec3 {
    let g = &grids.grids[m.grid as usize];
    let sigma_t = Vec3::from(m.sigma_t);
    let top = sigma_t.max_element();
    let o = to_grid(g, ray.origin);
    let d = dir_to_grid(g, ray.dir);
    let (t_enter, t_exit) = clip(g, o, d, t_end);
    let mut through = Vec3::ONE;
    if top <= 0.0 || t_enter >= t_exit {
        return through;
    }
    let mut tracker = MajorantTracker::new(g, o, d, (t_enter, t_exit), top, rng);
    loop {
        match tracker.step(grids, g, rng) {
            TrackStep::Cut => return Vec3::ZERO,
            TrackStep::Exit => return through,
            TrackStep::Crossed => {}
            TrackStep::Collision => {
                let dens = density(grids.voxels, g, o + tracker.t * d);
                let rate = tracker.majorant * top;
                through *= (Vec3::ONE - sigma_t * (dens / rate)).max(Vec3::ZERO);
                if through.max_element() <= 0.0 {
                    return Vec3::ZERO;
                }
            }
        }
    }
}
