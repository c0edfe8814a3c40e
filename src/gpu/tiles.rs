//! Splits a batch into tiles of pixels so that no single GPU submission runs longer than a
//! target, on any scene: a watchdog (desktop drivers kill submissions after about 2 s) must
//! never see a long one, however slow each sample is. Pixels are independent, so the tiling
//! never changes the image.

use std::time::Duration;

/// Tiles are whole workgroups (8×8 pixels, `crate::kernel::source::WORKGROUP_SIZE`), except at the
/// image's right and bottom edges.
const GRANULE: u32 = 8;

/// A rectangle of pixels: origin and size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// Walks an image in tiles sized from the measured cost of the previous submissions.
#[derive(Clone, Debug)]
pub struct TilePlanner {
    /// Wanted duration of one submission.
    pub target: Duration,
    /// Measured seconds per pixel-sample, once a submission has been timed.
    seconds_per_path: Option<f64>,
}

/// The first submission of a renderer, before any is timed: 64×64 pixels.
const FIRST_TILE_PIXELS: f64 = 4096.0;
/// A tile grows at most this much from one submission to the next, so one fast outlier (a
/// tile of sky) cannot make the next one long.
const MAX_GROWTH: f64 = 4.0;

impl TilePlanner {
    pub fn new(target: Duration) -> TilePlanner {
        TilePlanner {
            target,
            seconds_per_path: None,
        }
    }

    /// Records that `pixels` pixels × `samples` samples took `took`.
    pub fn record(&mut self, pixels: u64, samples: u32, took: Duration) {
        let paths = (pixels * samples as u64).max(1) as f64;
        self.seconds_per_path = Some(took.as_secs_f64() / paths);
    }

    /// How many pixels the next submission of `samples` samples per pixel may cover to last
    /// about the target, given the last tile's size (growth is capped).
    pub fn pixel_budget(&self, samples: u32, last_tile_pixels: Option<u64>) -> u64 {
        let Some(per_path) = self.seconds_per_path else {
            return FIRST_TILE_PIXELS as u64;
        };
        let budget = self.target.as_secs_f64() / (per_path.max(1e-12) * samples.max(1) as f64);
        let capped = match last_tile_pixels {
            Some(last) => budget.min(last as f64 * MAX_GROWTH),
            None => budget,
        };
        capped.max(1.0).min(u64::MAX as f64 / 2.0) as u64
    }
}

/// The next tile from the cursor (`x`, `y`) of an image walked in bands of rows: a whole-width
/// band of as many 8-row granules as `budget` pixels allow, or, when not even 8 full rows
/// fit, part of an 8-row band (at least one 8×8 workgroup).
pub fn next_tile(width: u32, height: u32, x: u32, y: u32, budget: u64) -> Tile {
    let band = GRANULE.min(height - y);
    if x == 0 && budget >= width as u64 * band as u64 {
        let rows = (budget / width as u64).min((height - y) as u64) as u32;
        let rows = if rows < height - y {
            (rows / GRANULE * GRANULE).max(band)
        } else {
            rows
        };
        return Tile {
            x: 0,
            y,
            width,
            height: rows,
        };
    }
    let columns = (budget / band as u64).min((width - x) as u64) as u32;
    let columns = if columns < width - x {
        (columns / GRANULE * GRANULE).max(GRANULE.min(width - x))
    } else {
        columns
    };
    Tile {
        x,
        y,
        width: columns,
        height: band,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Walks the whole image with a fixed budget and checks the tiles cover it exactly once.
    fn walk(width: u32, height: u32, budget: u64) -> Vec<Tile> {
        let (mut x, mut y) = (0, 0);
        let mut tiles = Vec::new();
        let mut covered = vec![0u8; (width * height) as usize];
        while y < height {
            let t = next_tile(width, height, x, y, budget);
            for py in t.y..t.y + t.height {
                for px in t.x..t.x + t.width {
                    covered[(py * width + px) as usize] += 1;
                }
            }
            x += t.width;
            if x >= width {
                x = 0;
                y += t.height;
            }
            tiles.push(t);
        }
        assert!(
            covered.iter().all(|&c| c == 1),
            "{width}x{height} budget {budget}"
        );
        tiles
    }

    #[test]
    fn tiles_cover_every_pixel_once_at_any_budget() {
        for (w, h) in [(1, 1), (7, 5), (48, 48), (100, 37), (512, 512)] {
            for budget in [1, 8, 63, 64, 65, 300, 4096, 1 << 20] {
                let tiles = walk(w, h, budget);
                if budget >= (w * h) as u64 {
                    assert_eq!(tiles.len(), 1);
                }
                // No tile is larger than the budget, except the smallest possible one.
                for t in tiles {
                    let pixels = (t.width * t.height) as u64;
                    assert!(pixels <= budget.max(64), "{t:?} budget {budget}");
                }
            }
        }
    }
}
