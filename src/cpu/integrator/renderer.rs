//! The CPU renderer: the kernel's entry point run over all pixels, rows in parallel (rayon).

use crate::cpu::integrator::pixel::{render_pixel, PixelStats};
use crate::cpu::integrator::splat::SplatFilm;
use crate::cpu::scene_refs::SceneRefs;
use crate::image::aov::Aovs;
use crate::image::output::Image;
use crate::kernel::types::INTEGRATOR_BDPT;
use crate::kernel::KernelScene;
use crate::render::accumulation::variance_of_mean;
use crate::render::accumulation::{Accumulation, PixelCounts};
use crate::render::{check_size, Renderer};
use anyhow::{anyhow, Result};
use rayon::prelude::*;

pub struct CpuRenderer {
    scene: KernelScene,
    stats: Vec<PixelStats>,
    /// Light tracing's splats (bidirectional path tracing only).
    film: SplatFilm,
    /// Which pixels adaptive sampling has stopped, and at how many samples.
    counts: PixelCounts,
    samples: u32,
    first_sample: u32,
    segments: u64,
}

impl CpuRenderer {
    pub fn new(scene: &KernelScene) -> CpuRenderer {
        let pixels = scene.params.width as usize * scene.params.height as usize;
        CpuRenderer {
            scene: scene.clone(),
            stats: vec![PixelStats::default(); pixels],
            film: SplatFilm::new(pixels),
            counts: PixelCounts::new(pixels),
            samples: 0,
            first_sample: 0,
            segments: 0,
        }
    }
}

impl Renderer for CpuRenderer {
    fn add_samples(&mut self, count: u32) -> Result<()> {
        let mut params = self.scene.params;
        params.sample_start = self.first_sample + self.samples;
        params.accumulated_samples = self.samples;
        params.sample_count = count;
        let refs = SceneRefs::of(&self.scene, &params);
        let width = params.width as usize;
        let film = &self.film;
        let segments: u64 = self
            .stats
            .par_chunks_mut(width)
            .enumerate()
            .map(|(y, row)| {
                let mut segments = 0u64;
                for (x, stats) in row.iter_mut().enumerate() {
                    segments += render_pixel(&refs, x as u32, y as u32, stats, film) as u64;
                }
                segments
            })
            .sum();
        self.samples += count;
        self.segments += segments;
        Ok(())
    }

    fn samples(&self) -> u32 {
        self.samples
    }

    fn first_sample(&self) -> u32 {
        self.first_sample
    }

    fn read_accumulation(&mut self) -> Result<Accumulation> {
        Ok(Accumulation {
            width: self.scene.params.width,
            height: self.scene.params.height,
            count: self.samples,
            counts: self.counts.counts(self.samples),
            mean: self.stats.iter().map(|s| s.mean.into()).collect(),
            m2: self.stats.iter().map(|s| s.m2.into()).collect(),
            splats: if self.scene.params.integrator == INTEGRATOR_BDPT {
                self.film.words()
            } else {
                Vec::new()
            },
            splat_scale: self.scene.params.splat_scale,
            batches: 0,
        })
    }

    fn load_accumulation(&mut self, first_sample: u32, state: Option<&Accumulation>) -> Result<()> {
        self.reset()?;
        if let Some(state) = state {
            check_size(&self.scene.params, state)?;
            for (stats, (mean, m2)) in self.stats.iter_mut().zip(state.mean.iter().zip(&state.m2)) {
                stats.mean = (*mean).into();
                stats.m2 = (*m2).into();
            }
            self.samples = state.count;
            self.film.load(&state.splats);
            self.counts.load(&state.counts, state.count);
            for (i, stats) in self.stats.iter_mut().enumerate() {
                stats.stopped = self.counts.is_stopped(i);
            }
        }
        self.first_sample = first_sample;
        Ok(())
    }

    fn read_mean(&mut self) -> Result<Image> {
        Ok(self.read_accumulation()?.mean_image())
    }

    fn read_variance(&mut self) -> Result<Image> {
        let counts = self.counts.counts(self.samples);
        Ok(Image {
            width: self.scene.params.width,
            height: self.scene.params.height,
            pixels: self
                .stats
                .iter()
                .zip(counts)
                .map(|(s, n)| variance_of_mean(s.m2.into(), n))
                .collect(),
        })
    }

    fn read_aovs(&mut self) -> Result<Aovs> {
        if self.scene.params.aovs == 0 {
            return Err(anyhow!(
                "this render does not accumulate AOVs (Params::aovs is 0)"
            ));
        }
        let albedo_depth: Vec<[f32; 4]> = self
            .stats
            .iter()
            .map(|s| s.aov.albedo.extend(s.aov.depth).into())
            .collect();
        let normal: Vec<[f32; 4]> = self
            .stats
            .iter()
            .map(|s| s.aov.normal.extend(0.0).into())
            .collect();
        let p = &self.scene.params;
        Ok(Aovs::from_vec4s(p.width, p.height, &albedo_depth, &normal))
    }

    fn reset(&mut self) -> Result<()> {
        self.stats.fill(PixelStats::default());
        self.film.clear();
        self.counts.reset();
        self.samples = 0;
        self.segments = 0;
        Ok(())
    }

    fn segments_traced(&self) -> Option<u64> {
        Some(self.segments)
    }

    fn stop_pixels(&mut self, stop: &[bool]) -> Result<()> {
        for i in self.counts.stop(stop, self.samples) {
            self.stats[i].stopped = true;
        }
        Ok(())
    }

    fn pixel_counts(&self) -> Vec<u32> {
        self.counts.counts(self.samples)
    }

    fn active_pixels(&self) -> usize {
        self.counts.active()
    }

    fn nonfinite_samples(&self) -> u64 {
        self.stats.iter().map(|s| s.nonfinite as u64).sum()
    }

    fn device_name(&self) -> String {
        "cpu".into()
    }

    fn backend_name(&self) -> String {
        format!("cpu ({} threads)", rayon::current_num_threads())
    }
}
