//! The BVH over the laid-out primitives, for scenes large enough to want one: a single tree,
//! or, where meshes are instanced, two levels (a top-level tree with one leaf per instance,
//! then each instanced mesh's own tree) and the instances' transforms.

use super::KernelScene;
use crate::error::InputError;
use crate::kernel::bvh;
use crate::kernel::types;
use crate::scene::Scene;
use glam::Vec3;

/// An instance's transforms as the kernel reads them: `placement`'s rows, and its inverse's,
/// inverted in f64 so the two agree to f32's precision.
fn kernel_instance(placement: &glam::Mat4, first_triangle: u32, count: u32) -> types::Instance {
    let inverse = placement.as_dmat4().inverse().as_mat4();
    let rows = |m: &glam::Mat4| [0, 1, 2].map(|i| m.row(i).to_array());
    types::Instance {
        to_world: rows(placement),
        to_object: rows(&inverse),
        blas_root: 0,
        first_triangle,
        triangle_count: count,
        _pad: 0,
    }
}

/// The box, in the scene's coordinates, of a mesh whose own box is (low, high) placed by
/// `placement`: its eight corners placed, and widened a little, since a ray is tested against
/// the mesh in the mesh's coordinates, so a hit on the box's boundary may round to just
/// outside the exact placed box (a larger box costs a little time, never a hit).
fn placed_box(placement: &glam::Mat4, low: Vec3, high: Vec3) -> (Vec3, Vec3) {
    let m = placement.as_dmat4();
    let (mut min, mut max) = (glam::DVec3::INFINITY, glam::DVec3::NEG_INFINITY);
    for corner in 0..8 {
        let pick = |bit: usize, axis: usize| {
            if corner & bit != 0 {
                high[axis]
            } else {
                low[axis]
            }
        };
        let p = m.transform_point3(glam::DVec3::new(
            pick(1, 0) as f64,
            pick(2, 1) as f64,
            pick(4, 2) as f64,
        ));
        (min, max) = (min.min(p), max.max(p));
    }
    let margin = 1e-5 * ((max - min).max_element() + min.abs().max(max.abs()).max_element());
    ((min - margin).as_vec3(), (max + margin).as_vec3())
}

impl Scene {
    /// Builds `scene`'s BVH (its spheres, quads and triangles laid out) into its BVH arrays and
    /// instances, where [`bvh::wants_bvh`] says the scene is large enough for one.
    pub(super) fn lay_out_bvh(&self, scene: &mut KernelScene) -> Result<(), InputError> {
        if !bvh::wants_bvh(
            scene.spheres.len(),
            scene.quads.len(),
            scene.triangles.len(),
        ) {
            return Ok(());
        }
        // Validation bounds the primitive count far below what a reference holds, and the
        // builder bounds the tree's depth by the traversal stack: this error is a backstop.
        let cannot = |e: String| InputError(format!("the scene cannot be rendered: {e}"));
        let tree = if self.instanced.is_empty() {
            bvh::build(&scene.spheres, &scene.quads, &scene.triangles).map_err(cannot)?
        } else {
            let (tree, instances) = self.two_level(scene).map_err(cannot)?;
            scene.instances = instances;
            tree
        };
        // The wide tree only without instances: its traversal has no instance leaves, and
        // an instance's mesh is walked in the binary tree (shaders/traverse/blas.wgsl),
        // which the wide variant does not bind. Scenes with instances keep the binary one.
        if scene.instances.is_empty() {
            scene.bvh_wide_nodes = tree.wide_nodes();
        }
        scene.bvh_nodes = tree.nodes;
        scene.bvh_primitives = tree.primitives;
        scene.bvh_build_seconds = tree.build_seconds;
        Ok(())
    }

    /// The two-level structure over `scene`'s primitives (laid out by [`Scene::lay_out`]): the
    /// top-level BVH over the spheres, quads and triangles placed as they are and one leaf
    /// primitive per instance, then each instanced mesh's own BVH after it in the same
    /// arrays, and the instances' transforms. Memory grows with unique geometry: a mesh's
    /// triangles and BVH are stored once, whatever its number of instances.
    fn two_level(&self, scene: &KernelScene) -> Result<(bvh::Bvh, Vec<types::Instance>), String> {
        let own = self.triangles.len();
        let mut first_triangle = own as u32;
        let mut instances = Vec::new();
        let mut boxes = Vec::new();
        // Each mesh's bottom level is built now and appended once the top level is laid out.
        let mut meshes = Vec::with_capacity(self.instanced.len());
        for mesh in &self.instanced {
            let count = mesh.triangles.len();
            let range = first_triangle as usize..first_triangle as usize + count;
            let bottom = bvh::build(&[], &[], &scene.triangles[range.clone()])?;
            let root = &bottom.nodes[0];
            let (low, high) = (Vec3::from(root.min), Vec3::from(root.max));
            for placement in &mesh.placements {
                boxes.push(placed_box(placement, low, high));
                instances.push(kernel_instance(placement, first_triangle, count as u32));
            }
            meshes.push((
                instances.len() - mesh.placements.len()..instances.len(),
                range,
            ));
            first_triangle += count as u32;
        }
        let mut tree = bvh::build_top_level(
            &scene.spheres,
            &scene.quads,
            &scene.triangles[..own],
            &boxes,
        )?;
        for (placed, range) in meshes {
            let first = range.start as u32;
            let root = bvh::append_bottom_level(&mut tree, &scene.triangles[range], first)?;
            for instance in &mut instances[placed] {
                instance.blas_root = root;
            }
        }
        Ok((tree, instances))
    }
}
