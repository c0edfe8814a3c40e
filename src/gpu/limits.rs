//! The device limits a scene must fit before it is uploaded: each of the scene's arrays is one
//! storage binding, and a binding holds at most `max_storage_buffer_binding_size` bytes
//! (128 MiB on lavapipe and many GPUs). Over the limit is the user's to fix (exit code 2).

use crate::error::InputError;
use crate::scene::KernelScene;

/// An error naming the largest array, its size and the device's limit, when it does not fit.
pub fn check_scene_fits(scene: &KernelScene, max_storage_binding: u64) -> Result<(), InputError> {
    let (name, bytes) = scene.largest_array();
    if bytes > max_storage_binding {
        return Err(InputError(format!(
            "the scene's {name} need {:.1} MiB in one GPU storage binding, but this device binds \
             at most {:.1} MiB ({} triangles, {} BVH nodes; {:.1} MiB in all); use --cpu or a smaller mesh",
            bytes as f64 / (1 << 20) as f64,
            max_storage_binding as f64 / (1 << 20) as f64,
            scene.triangles.len(),
            scene.bvh_nodes.len(),
            scene.scene_bytes() as f64 / (1 << 20) as f64,
        )));
    }
    Ok(())
}
