//! The CPU renderer: the kernel's entry point run over all pixels, rows in parallel (rayon).

use super::trace::{render_pixel, SceneRefs};
use crate::render::Renderer;
use crate::scene::KernelScene;
use anyhow::Result;
use rayon::prelude::*;

pub struct CpuRenderer {
    scene: KernelScene,
    sums: Vec<[f32; 3]>,
}

impl CpuRenderer {
    pub fn new(scene: &KernelScene) -> CpuRenderer {
        let pixels = scene.params.width as usize * scene.params.height as usize;
        CpuRenderer {
            scene: scene.clone(),
            sums: vec![[0.0; 3]; pixels],
        }
    }
}

impl Renderer for CpuRenderer {
    fn add_samples(&mut self, sample_start: u32, sample_count: u32) -> Result<()> {
        let mut params = self.scene.params;
        params.sample_start = sample_start;
        params.sample_count = sample_count;
        let refs = SceneRefs {
            params: &params,
            spheres: &self.scene.spheres,
            quads: &self.scene.quads,
            materials: &self.scene.materials,
        };
        let width = params.width as usize;
        self.sums
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, sum) in row.iter_mut().enumerate() {
                    let s = render_pixel(&refs, x as u32, y as u32);
                    // As the kernel does: one f32 add of the batch's sum per pixel.
                    *sum = [sum[0] + s.x, sum[1] + s.y, sum[2] + s.z];
                }
            });
        Ok(())
    }

    fn read_sums(&mut self) -> Result<Vec<[f32; 3]>> {
        Ok(self.sums.clone())
    }

    fn reset(&mut self) -> Result<()> {
        self.sums.fill([0.0; 3]);
        Ok(())
    }

    fn device_name(&self) -> String {
        "cpu".into()
    }

    fn backend_name(&self) -> String {
        format!("cpu ({} threads)", rayon::current_num_threads())
    }
}
