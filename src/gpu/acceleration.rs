//! The acceleration structure the hardware traversal (`shaders/traverse/hardware.wgsl`)
//! traces with ray queries: a TLAS over triangle geometry holding the triangles placed as they
//! are, box (AABB) geometry holding the spheres and quads, and one triangle BLAS per instanced
//! mesh (its triangles in its own coordinates, stored once) with one TLAS instance per
//! placement, transformed by the placement. The kernel tests every candidate with glint's own
//! exact tests. Each primitive's reference ((kind << PRIMITIVE_KIND_SHIFT) | index) is in one
//! buffer, where a candidate's is at its instance's custom data plus its primitive index; the
//! placements take the TLAS's first slots, so a candidate on a placement's mesh is hit through
//! the instance whose index is its TLAS instance index.

use super::context::GpuContext;
use crate::kernel::types::{
    PRIMITIVE_INDEX_MASK, PRIMITIVE_INSTANCE, PRIMITIVE_KIND_SHIFT, PRIMITIVE_QUAD,
    PRIMITIVE_SPHERE, PRIMITIVE_TRIANGLE,
};
use crate::kernel::KernelScene;
use anyhow::{anyhow, Result};
use glam::Vec3;
use wgpu::util::DeviceExt;

/// The scene's primitives as the hardware takes them, before upload.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HardwareGeometry {
    /// Three vertices per triangle placed as it is (no index buffer), in
    /// `triangle_references`' order: each triangle widened in its plane ([`widened_triangle`]).
    pub vertices: Vec<[f32; 3]>,
    pub triangle_references: Vec<u32>,
    /// (min, max) per sphere or quad, in `box_references`' order.
    pub boxes: Vec<[f32; 6]>,
    pub box_references: Vec<u32>,
    /// Each instanced mesh once, in its own coordinates, in the kernel's order.
    pub meshes: Vec<MeshGeometry>,
    /// Per instance (in `KernelScene::instances`' order): its mesh's index in `meshes`.
    pub instance_meshes: Vec<usize>,
}

/// An instanced mesh's triangles as its BLAS takes them: widened like the others, in its own
/// coordinates, with their references (triangle indices in the kernel's arrays).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshGeometry {
    pub vertices: Vec<[f32; 3]>,
    pub triangle_references: Vec<u32>,
}

/// How much each box is widened on every side, relative to the size of its coordinates and
/// its extent: 2⁻¹², so the hardware's box test (whose rounding is not glint's) never drops a
/// primitive glint's exact test hits, a flat quad's box above all. A wider box only proposes
/// a few more candidates, which the exact test rejects.
const BOX_PADDING: f32 = 1.0 / 4096.0;

fn padded_box(min: Vec3, max: Vec3) -> [f32; 6] {
    let size = min.abs().max(max.abs()).max_element() + (max - min).max_element();
    let pad = Vec3::splat(size * BOX_PADDING + f32::MIN_POSITIVE);
    let (min, max) = (min - pad, max + pad);
    [min.x, min.y, min.z, max.x, max.y, max.z]
}

/// The triangle (a, b, c) with each edge moved outward in its plane by 2⁻¹⁴ of the size of
/// its coordinates (and its longest edge): the hardware's triangle test rounds differently from
/// glint's watertight one (shaders/geometry/triangle.wgsl), and a ray through an edge that glint's test
/// gives to one triangle could otherwise find the hardware proposing neither of the two (as
/// measured on lavapipe). Widened, the hardware proposes every triangle glint's test hits, and
/// the few beyond, near the edges, glint's test rejects. A degenerate triangle (no plane), which
/// glint's test never hits, is kept as it is.
pub fn widened_triangle(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [[f32; 3]; 3] {
    use glam::DVec3;
    let p = [a, b, c].map(|v| DVec3::from(v.map(f64::from)));
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    if !n.is_finite() || n.length_squared() <= 0.0 {
        return [a, b, c];
    }
    let size = p.iter().map(|v| v.abs().max_element()).fold(0.0, f64::max)
        + (0..3)
            .map(|i| (p[(i + 1) % 3] - p[i]).length())
            .fold(0.0, f64::max);
    let delta = size / 16384.0;
    // The outward normal, in the plane, of the edge from vertex i to vertex i + 1.
    let outward = |i: usize| (p[(i + 1) % 3] - p[i]).cross(n).normalize();
    std::array::from_fn(|i| {
        // The edges into and out of vertex i, each moved out by delta, meet here.
        let (m1, m2) = (outward((i + 2) % 3), outward(i));
        let moved = p[i] + delta * (m1 + m2) / (1.0 + m1.dot(m2)).max(1e-6);
        moved.as_vec3().to_array()
    })
}

impl HardwareGeometry {
    /// The primitives the traversal must see: those of the scene's BVH where it has one (all
    /// but exact copies, which by the closest-hit rule no ray sees: src/kernel/bvh/mod.rs; an
    /// instanced mesh's, those of its own BVH, without its copies), else every sphere and quad
    /// (a scene without a BVH has no triangles).
    pub fn of(scene: &KernelScene) -> HardwareGeometry {
        let references: Vec<u32> = if scene.bvh_primitives.is_empty() {
            let spheres = (0..scene.spheres.len() as u32)
                .map(|i| (PRIMITIVE_SPHERE << PRIMITIVE_KIND_SHIFT) | i);
            let quads =
                (0..scene.quads.len() as u32).map(|i| (PRIMITIVE_QUAD << PRIMITIVE_KIND_SHIFT) | i);
            spheres.chain(quads).collect()
        } else {
            let mut sorted = scene.bvh_primitives.clone();
            sorted.sort_unstable();
            sorted
        };
        let mut geometry = HardwareGeometry::default();
        // The meshes' first triangles, in order (the kernel lays the meshes out one after
        // another, each placed by consecutive instances).
        let mut mesh_starts: Vec<u32> = Vec::new();
        for instance in &scene.instances {
            if mesh_starts.last() != Some(&instance.first_triangle) {
                mesh_starts.push(instance.first_triangle);
                geometry.meshes.push(MeshGeometry::default());
            }
            geometry.instance_meshes.push(mesh_starts.len() - 1);
        }
        let own_triangles = mesh_starts.first().map_or(u32::MAX, |&first| first);
        for reference in references {
            let index = (reference & PRIMITIVE_INDEX_MASK) as usize;
            match reference >> PRIMITIVE_KIND_SHIFT {
                // The instances themselves are the TLAS's placements.
                PRIMITIVE_INSTANCE => {}
                PRIMITIVE_TRIANGLE if index as u32 >= own_triangles => {
                    let mesh = mesh_starts.partition_point(|&first| first <= index as u32) - 1;
                    let t = &scene.triangles[index];
                    let m = &mut geometry.meshes[mesh];
                    m.vertices.extend(widened_triangle(t.v0, t.v1, t.v2));
                    m.triangle_references.push(reference);
                }
                PRIMITIVE_TRIANGLE => {
                    let t = &scene.triangles[index];
                    geometry.vertices.extend(widened_triangle(t.v0, t.v1, t.v2));
                    geometry.triangle_references.push(reference);
                }
                PRIMITIVE_SPHERE => {
                    let s = &scene.spheres[index];
                    let c = Vec3::from(s.center);
                    geometry.boxes.push(padded_box(c - s.radius, c + s.radius));
                    geometry.box_references.push(reference);
                }
                _ => {
                    let q = &scene.quads[index];
                    let p = Vec3::from(q.corner);
                    let (u, v) = (Vec3::from(q.edge_u), Vec3::from(q.edge_v));
                    let corners = [p, p + u, p + v, p + u + v];
                    let min = corners.iter().fold(Vec3::INFINITY, |a, &b| a.min(b));
                    let max = corners.iter().fold(Vec3::NEG_INFINITY, |a, &b| a.max(b));
                    geometry.boxes.push(padded_box(min, max));
                    geometry.box_references.push(reference);
                }
            }
        }
        geometry
    }

    /// Every reference: the triangles', then the boxes', then each mesh's.
    pub fn references(&self) -> Vec<u32> {
        let mut all = self.triangle_references.clone();
        all.extend(&self.box_references);
        for mesh in &self.meshes {
            all.extend(&mesh.triangle_references);
        }
        all
    }

    /// Where each mesh's references start in [`HardwareGeometry::references`]: the custom
    /// data of its placements.
    pub fn mesh_reference_starts(&self) -> Vec<usize> {
        let mut next = self.triangle_references.len() + self.box_references.len();
        self.meshes
            .iter()
            .map(|mesh| {
                let start = next;
                next += mesh.triangle_references.len();
                start
            })
            .collect()
    }
}

/// The built TLAS and what the kernel reads beside it; the BLASes and their inputs are kept
/// alive with it.
pub struct AccelerationStructure {
    pub tlas: wgpu::Tlas,
    /// [`HardwareGeometry::references`] (one placeholder where there are none).
    pub references: wgpu::Buffer,
    _blases: Vec<wgpu::Blas>,
    _inputs: Vec<wgpu::Buffer>,
    /// Seconds the build took on the device, upload included.
    pub build_seconds: f64,
}

/// The row-major 3×4 identity: the triangles placed as they are, and the boxes, are in world
/// space.
const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// The instance custom data holds 24 bits.
const MAX_CUSTOM_DATA: usize = (1 << 24) - 1;

/// What one BLAS holds, before upload.
enum BlasInput<'a> {
    /// Three widened vertices per triangle.
    Triangles(&'a [[f32; 3]]),
    Boxes(&'a [[f32; 6]]),
}

/// One BLAS's geometry size, which its creation and its build both take.
enum BlasSize {
    Triangles(wgpu::BlasTriangleGeometrySizeDescriptor),
    Boxes(wgpu::BlasAABBGeometrySizeDescriptor),
}

impl BlasInput<'_> {
    fn size(&self) -> BlasSize {
        let flags = wgpu::AccelerationStructureGeometryFlags::OPAQUE;
        match self {
            BlasInput::Triangles(vertices) => {
                BlasSize::Triangles(wgpu::BlasTriangleGeometrySizeDescriptor {
                    vertex_format: wgpu::VertexFormat::Float32x3,
                    vertex_count: vertices.len() as u32,
                    index_format: None,
                    index_count: None,
                    flags,
                })
            }
            BlasInput::Boxes(boxes) => BlasSize::Boxes(wgpu::BlasAABBGeometrySizeDescriptor {
                primitive_count: boxes.len() as u32,
                flags,
            }),
        }
    }

    /// Its buffer's label and contents.
    fn contents(&self) -> (&'static str, &[u8]) {
        match self {
            BlasInput::Triangles(vertices) => ("BLAS vertices", bytemuck::cast_slice(vertices)),
            BlasInput::Boxes(boxes) => ("BLAS boxes", bytemuck::cast_slice(boxes)),
        }
    }
}

/// Builds `scene`'s acceleration structure on `ctx`'s device, which must have ray queries.
/// A scene over the device's limits is an error naming the limit.
pub fn build(ctx: &GpuContext, scene: &KernelScene) -> Result<AccelerationStructure> {
    if !ctx.has_ray_queries() {
        return Err(anyhow!(
            "{} has no ray queries (wgpu's EXPERIMENTAL_RAY_QUERY), which the hardware traversal needs",
            ctx.device_name()
        ));
    }
    let started = std::time::Instant::now();
    let device = &ctx.device;
    let limits = device.limits();
    let geometry = HardwareGeometry::of(scene);
    check_primitive_counts(ctx, &geometry)?;
    let triangles = geometry.triangle_references.len();
    let references = geometry.references();
    if references.len() > MAX_CUSTOM_DATA {
        return Err(anyhow!(
            "the scene's {} primitives (its instanced meshes' counted once) are more than the \
             hardware traversal can reference ({MAX_CUSTOM_DATA}); use --traversal software",
            references.len()
        ));
    }
    // An empty scene still needs an instance: one box BLAS holding one inactive box (NaN).
    let mut boxes_in = geometry.boxes.clone();
    if boxes_in.is_empty() && triangles == 0 && scene.instances.is_empty() {
        boxes_in.push([f32::NAN; 6]);
    }
    // (what it holds, its instances' custom data); the meshes first, so that the placements,
    // which take the TLAS's first slots, are in the instances' order.
    let mut blas_inputs: Vec<(BlasInput, u32)> = Vec::new();
    let mesh_starts = geometry.mesh_reference_starts();
    for (mesh, &start) in geometry.meshes.iter().zip(&mesh_starts) {
        blas_inputs.push((BlasInput::Triangles(&mesh.vertices), start as u32));
    }
    if triangles > 0 {
        blas_inputs.push((BlasInput::Triangles(&geometry.vertices), 0));
    }
    if !boxes_in.is_empty() {
        blas_inputs.push((BlasInput::Boxes(&boxes_in), triangles as u32));
    }
    // (BLAS index, row-major 3×4 transform, custom data) per TLAS instance: the placements,
    // then the world-space BLASes.
    let mut tlas_instances: Vec<(usize, [f32; 12], u32)> = scene
        .instances
        .iter()
        .zip(&geometry.instance_meshes)
        .map(|(instance, &mesh)| {
            let transform: [f32; 12] = bytemuck::cast(instance.to_world);
            (mesh, transform, blas_inputs[mesh].1)
        })
        .collect();
    for (blas, input) in blas_inputs.iter().enumerate().skip(geometry.meshes.len()) {
        tlas_instances.push((blas, IDENTITY, input.1));
    }
    let most_instances = limits.max_tlas_instance_count as usize;
    if tlas_instances.len() > most_instances {
        return Err(anyhow!(
            "the scene's {} instances (and {} world-space structures) are more than {} allows in \
             one acceleration structure ({most_instances} instances); use --traversal software",
            scene.instances.len(),
            tlas_instances.len() - scene.instances.len(),
            ctx.device_name()
        ));
    }
    let flags = wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE;
    let sizes: Vec<BlasSize> = blas_inputs.iter().map(|(input, _)| input.size()).collect();
    let blases = create_blases(device, &sizes);
    let inputs: Vec<wgpu::Buffer> = blas_inputs
        .iter()
        .map(|(input, _)| {
            let (label, contents) = input.contents();
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::BLAS_INPUT,
            })
        })
        .collect();
    let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
        label: Some("glint TLAS"),
        max_instances: tlas_instances.len() as u32,
        flags,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    });
    for (slot, &(blas, transform, custom_data)) in tlas_instances.iter().enumerate() {
        tlas[slot] = Some(wgpu::TlasInstance::new(
            &blases[blas],
            transform,
            custom_data,
            0xff,
        ));
    }
    let entries = blas_build_entries(&sizes, &blases, &inputs);
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.build_acceleration_structures(entries.iter(), std::iter::once(&tlas));
    ctx.queue.submit([encoder.finish()]);
    ctx.wait_idle()
        .map_err(|e| e.context("building the acceleration structure"))?;
    let references = super::upload::storage_buffer(ctx, "hardware references", &references);
    Ok(AccelerationStructure {
        tlas,
        references,
        _blases: blases,
        _inputs: inputs,
        build_seconds: started.elapsed().as_secs_f64(),
    })
}

/// Refuses a scene with more primitives in one structure than the device allows.
fn check_primitive_counts(ctx: &GpuContext, geometry: &HardwareGeometry) -> Result<()> {
    let triangles = geometry.triangle_references.len();
    let boxes = geometry.boxes.len();
    let most = ctx.device.limits().max_blas_primitive_count as usize;
    let largest_mesh = geometry
        .meshes
        .iter()
        .map(|m| m.triangle_references.len())
        .max()
        .unwrap_or(0);
    for (count, what) in [
        (triangles, "triangles"),
        (boxes, "spheres and quads"),
        (largest_mesh, "triangles of one instanced mesh"),
    ] {
        if count > most {
            return Err(anyhow!(
                "the scene's {count} {what} are more than {} allows in one acceleration structure \
                 ({most}); use --traversal software",
                ctx.device_name()
            ));
        }
    }
    Ok(())
}

/// One empty BLAS per size, for the build to fill.
fn create_blases(device: &wgpu::Device, sizes: &[BlasSize]) -> Vec<wgpu::Blas> {
    let blas_descriptor = wgpu::CreateBlasDescriptor {
        label: Some("glint BLAS"),
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    };
    sizes
        .iter()
        .map(|size| {
            let descriptors = match size {
                BlasSize::Triangles(s) => wgpu::BlasGeometrySizeDescriptors::Triangles {
                    descriptors: vec![s.clone()],
                },
                BlasSize::Boxes(s) => wgpu::BlasGeometrySizeDescriptors::AABBs {
                    descriptors: vec![s.clone()],
                },
            };
            device.create_blas(&blas_descriptor, descriptors)
        })
        .collect()
}

/// What the build writes into each BLAS: its triangles' vertices or its boxes.
fn blas_build_entries<'a>(
    sizes: &'a [BlasSize],
    blases: &'a [wgpu::Blas],
    inputs: &'a [wgpu::Buffer],
) -> Vec<wgpu::BlasBuildEntry<'a>> {
    sizes
        .iter()
        .enumerate()
        .map(|(i, size)| wgpu::BlasBuildEntry {
            blas: &blases[i],
            geometry: match size {
                BlasSize::Triangles(size) => {
                    wgpu::BlasGeometries::TriangleGeometries(vec![wgpu::BlasTriangleGeometry {
                        size,
                        vertex_buffer: &inputs[i],
                        first_vertex: 0,
                        vertex_stride: size_of::<[f32; 3]>() as u64,
                        index_buffer: None,
                        first_index: None,
                        transform_buffer: None,
                        transform_buffer_offset: None,
                    }])
                }
                BlasSize::Boxes(size) => {
                    wgpu::BlasGeometries::AabbGeometries(vec![wgpu::BlasAabbGeometry {
                        size,
                        stride: size_of::<[f32; 6]>() as u64,
                        aabb_buffer: &inputs[i],
                        primitive_offset: 0,
                    }])
                }
            },
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A widened triangle holds the original one with a margin of at least delta on each
    /// edge, and stays in its plane.
    #[test]
    fn widened_triangles_hold_the_original_with_a_margin() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 2.0, 0.0]);
        let w = widened_triangle(a, b, c);
        // 2⁻¹⁴ of the largest coordinate (4) and the longest edge (√20).
        let delta = (4.0 + 20f32.sqrt()) / 16384.0;
        assert!(w.iter().all(|v| v[2] == 0.0));
        // The right angle at a moves by delta along both axes, outward.
        assert!((w[0][0] + delta).abs() < 1e-6 && (w[0][1] + delta).abs() < 1e-6);
        // Each widened edge line is delta beyond the original one: the hypotenuse's too.
        let n = glam::Vec2::new(2.0, 4.0).normalize();
        let offset =
            |v: [f32; 3]| glam::Vec2::new(v[0], v[1]).dot(n) - glam::Vec2::new(4.0, 0.0).dot(n);
        assert!((offset(w[1]) - delta).abs() < 1e-5 && (offset(w[2]) - delta).abs() < 1e-5);
        // A degenerate triangle is kept.
        let line = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        assert_eq!(widened_triangle(line[0], line[1], line[2]), line);
    }
}
