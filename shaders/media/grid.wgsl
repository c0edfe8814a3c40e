// Heterogeneous media from density grids (mirror: src/cpu/media/grid.rs, which explains the
// tracking): trilinear lookups, a DDA over the majorant blocks, delta tracking for free
// flights (spectral MIS over the channels) and ratio tracking for shadow rays. Compiled only
// into kernels of scenes with grid media (media/no_grid.wgsl stands in elsewhere).

@group(0) @binding(46) var<storage, read> grids: array<GridMedium>;
@group(0) @binding(47) var<storage, read> grid_voxels: array<f32>;

const MAX_TRACKING_STEPS: u32 = 256u;

fn grid_row(r: vec4<f32>, p: vec3<f32>) -> f32 {
    return r.x * p.x + r.y * p.y + r.z * p.z + r.w;
}

fn grid_row_linear(r: vec4<f32>, d: vec3<f32>) -> f32 {
    return r.x * d.x + r.y * d.y + r.z * d.z;
}

fn to_grid(g: GridMedium, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(grid_row(g.to_grid_x, p), grid_row(g.to_grid_y, p), grid_row(g.to_grid_z, p));
}

fn dir_to_grid(g: GridMedium, d: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(grid_row_linear(g.to_grid_x, d), grid_row_linear(g.to_grid_y, d), grid_row_linear(g.to_grid_z, d));
}

fn grid_voxel(g: GridMedium, x: i32, y: i32, z: i32) -> f32 {
    return grid_voxels[g.voxels + u32(x) + g.dims.x * (u32(y) + g.dims.y * u32(z))];
}

fn grid_lerp(a: f32, b: f32, w: f32) -> f32 {
    return a * (1.0 - w) + b * w;
}

fn grid_density(g: GridMedium, p: vec3<f32>) -> f32 {
    let dims = vec3<f32>(g.dims);
    let q = clamp(p - vec3<f32>(0.5), vec3<f32>(-1.0), dims);
    let f = floor(q);
    let w = q - f;
    let hi = vec3<i32>(g.dims) - vec3<i32>(1);
    let i0 = vec3<i32>(f);
    let a = clamp(i0, vec3<i32>(0), hi);
    let b = clamp(i0 + vec3<i32>(1), vec3<i32>(0), hi);
    let c00 = grid_lerp(grid_voxel(g, a.x, a.y, a.z), grid_voxel(g, b.x, a.y, a.z), w.x);
    let c10 = grid_lerp(grid_voxel(g, a.x, b.y, a.z), grid_voxel(g, b.x, b.y, a.z), w.x);
    let c01 = grid_lerp(grid_voxel(g, a.x, a.y, b.z), grid_voxel(g, b.x, a.y, b.z), w.x);
    let c11 = grid_lerp(grid_voxel(g, a.x, b.y, b.z), grid_voxel(g, b.x, b.y, b.z), w.x);
    return grid_lerp(grid_lerp(c00, c10, w.y), grid_lerp(c01, c11, w.y), w.z);
}

// The part of the ray inside the grid's box [0, dims]: (t_enter, t_exit).
fn grid_clip(g: GridMedium, o: vec3<f32>, d: vec3<f32>, t_max: f32) -> vec2<f32> {
    var t0 = 0.0;
    var t1 = t_max;
    for (var a = 0u; a < 3u; a++) {
        let size = f32(g.dims[a]);
        if d[a] != 0.0 {
            let inv = 1.0 / d[a];
            let ta = -o[a] * inv;
            let tb = (size - o[a]) * inv;
            t0 = max(t0, min(ta, tb));
            t1 = min(t1, max(ta, tb));
        } else if o[a] < 0.0 || o[a] > size {
            return vec2<f32>(1.0, 0.0);
        }
    }
    return vec2<f32>(t0, t1);
}

struct BlockWalk {
    cell: vec3<i32>,
    step: vec3<i32>,
    t_next: vec3<f32>,
    t_delta: vec3<f32>,
}

fn block_walk(g: GridMedium, o: vec3<f32>, d: vec3<f32>, t: f32) -> BlockWalk {
    let block = f32(g.block);
    let p = o + t * d;
    let top = vec3<i32>(g.blocks);
    let cells = floor(p / block);
    let cell = clamp(vec3<i32>(cells), vec3<i32>(0), top - vec3<i32>(1));
    var walk = BlockWalk(cell, vec3<i32>(0), vec3<f32>(NO_HIT), vec3<f32>(NO_HIT));
    for (var a = 0u; a < 3u; a++) {
        if d[a] > 0.0 {
            walk.step[a] = 1;
            walk.t_next[a] = (f32(cell[a] + 1) * block - o[a]) / d[a];
            walk.t_delta[a] = block / d[a];
        } else if d[a] < 0.0 {
            walk.step[a] = -1;
            walk.t_next[a] = (f32(cell[a]) * block - o[a]) / d[a];
            walk.t_delta[a] = -block / d[a];
        }
    }
    return walk;
}

fn block_walk_end(walk: BlockWalk) -> f32 {
    return min(walk.t_next.x, min(walk.t_next.y, walk.t_next.z));
}

fn block_walk_advance(g: GridMedium, walk: ptr<function, BlockWalk>) -> bool {
    let t = (*walk).t_next;
    var a = 2u;
    if t.x <= t.y && t.x <= t.z {
        a = 0u;
    } else if t.y <= t.z {
        a = 1u;
    }
    (*walk).cell[a] += (*walk).step[a];
    (*walk).t_next[a] += (*walk).t_delta[a];
    return (*walk).cell[a] >= 0 && (*walk).cell[a] < i32(g.blocks[a]);
}

fn grid_majorant(g: GridMedium, cell: vec3<i32>) -> f32 {
    return grid_voxels[g.majorants + u32(cell.x) + g.blocks.x * (u32(cell.y) + g.blocks.y * u32(cell.z))];
}

fn grid_normalised(r: vec3<f32>) -> vec3<f32> {
    let top = max(r.x, max(r.y, r.z));
    if top > 0.0 {
        return r / top;
    }
    return r;
}

// What one tracker step met (mirror: TrackStep).
const TRACK_CROSSED: u32 = 0u;
const TRACK_COLLISION: u32 = 1u;
const TRACK_EXIT: u32 = 2u;
const TRACK_CUT: u32 = 3u;

// Tentative collisions against the majorant blocks at `scale` per unit of majorant density:
// the walk both trackings share (mirror: MajorantTracker). One step is one block crossed or
// one collision, one iteration of the caller's loop.
struct MajorantTracker {
    walk: BlockWalk,
    t: f32,
    t_exit: f32,
    scale: f32,
    tau: f32,
    draw_tau: bool,
    steps: u32,
    majorant: f32,
    swept: f32,
}

fn majorant_tracker(g: GridMedium, o: vec3<f32>, d: vec3<f32>, span: vec2<f32>, scale: f32, rng: ptr<function, Rng>) -> MajorantTracker {
    let tau = -log(1.0 - rng_next(rng));
    return MajorantTracker(block_walk(g, o, d, span.x), span.x, span.y, scale, tau, false, 0u, 0.0, 0.0);
}

fn tracker_step(g: GridMedium, tr: ptr<function, MajorantTracker>, rng: ptr<function, Rng>) -> u32 {
    if (*tr).draw_tau {
        (*tr).tau = -log(1.0 - rng_next(rng));
        (*tr).draw_tau = false;
    }
    if (*tr).steps >= MAX_TRACKING_STEPS {
        return TRACK_CUT;
    }
    (*tr).steps += 1u;
    let t = (*tr).t;
    let end = max(min(block_walk_end((*tr).walk), (*tr).t_exit), t);
    let maj = grid_majorant(g, (*tr).walk.cell);
    let rate = maj * (*tr).scale;
    if rate > 0.0 && (*tr).tau < rate * (end - t) {
        let tc = t + (*tr).tau / rate;
        (*tr).swept += maj * (tc - t);
        (*tr).t = tc;
        (*tr).majorant = maj;
        (*tr).draw_tau = true;
        return TRACK_COLLISION;
    }
    (*tr).tau -= rate * (end - t);
    (*tr).swept += maj * (end - t);
    (*tr).t = end;
    if end >= (*tr).t_exit {
        return TRACK_EXIT;
    }
    // A pointer into *tr as an argument trips naga's SPIR-V writer: advance a copy.
    var walk = (*tr).walk;
    let inside = block_walk_advance(g, &walk);
    (*tr).walk = walk;
    if !inside {
        return TRACK_EXIT;
    }
    return TRACK_CROSSED;
}

fn grid_free_flight(m: Medium, ray: Ray, t_max: f32, rng: ptr<function, Rng>) -> FreeFlight {
    let g = grids[m.grid];
    let sigma_t = m.sigma_t;
    let sigma_s = m.sigma_s;
    let u_channel = rng_next(rng);
    let channel = min(u32(u_channel * 3.0), 2u);
    let lowest = min(sigma_t.x, min(sigma_t.y, sigma_t.z));
    let o = to_grid(g, ray.origin);
    let d = dir_to_grid(g, ray.dir);
    let span = grid_clip(g, o, d, t_max);
    var r = vec3<f32>(1.0);
    if span.x < span.y {
        var tracker = majorant_tracker(g, o, d, span, sigma_t[channel], rng);
        loop {
            let step = tracker_step(g, &tracker, rng);
            if step == TRACK_CUT {
                return FreeFlight(t_max, vec3<f32>(0.0), false);
            }
            if step == TRACK_CROSSED {
                continue;
            }
            r = grid_normalised(r * exp(-((sigma_t - vec3<f32>(lowest)) * tracker.swept)));
            tracker.swept = 0.0;
            if step == TRACK_EXIT {
                break;
            }
            let tc = tracker.t;
            let dens = grid_density(g, o + tc * d);
            if rng_next(rng) * tracker.majorant < dens {
                let pdf = dot(sigma_t * r, vec3<f32>(1.0 / 3.0));
                if pdf > 0.0 {
                    return FreeFlight(tc, sigma_s * r / pdf, true);
                }
                return FreeFlight(t_max, vec3<f32>(0.0), false);
            }
            r = grid_normalised(r * sigma_t);
        }
    }
    let survival = dot(r, vec3<f32>(1.0 / 3.0));
    if survival > 0.0 {
        return FreeFlight(t_max, r / survival, false);
    }
    return FreeFlight(t_max, vec3<f32>(0.0), false);
}

fn grid_transmittance(m: Medium, ray: Ray, t_end: f32, rng: ptr<function, Rng>) -> vec3<f32> {
    let g = grids[m.grid];
    let sigma_t = m.sigma_t;
    let top = max(sigma_t.x, max(sigma_t.y, sigma_t.z));
    let o = to_grid(g, ray.origin);
    let d = dir_to_grid(g, ray.dir);
    let span = grid_clip(g, o, d, t_end);
    var through = vec3<f32>(1.0);
    if top <= 0.0 || span.x >= span.y {
        return through;
    }
    var tracker = majorant_tracker(g, o, d, span, top, rng);
    loop {
        let step = tracker_step(g, &tracker, rng);
        if step == TRACK_CUT {
            return vec3<f32>(0.0);
        }
        if step == TRACK_EXIT {
            return through;
        }
        if step == TRACK_COLLISION {
            let dens = grid_density(g, o + tracker.t * d);
            let rate = tracker.majorant * top;
            through *= max(vec3<f32>(1.0) - sigma_t * (dens / rate), vec3<f32>(0.0));
            if max(through.x, max(through.y, through.z)) <= 0.0 {
                return vec3<f32>(0.0);
            }
        }
    }
    return through;
}
