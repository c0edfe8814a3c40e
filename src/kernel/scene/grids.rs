//! Grid media's arrays (`src/scene/grid.rs`): for each grid a volume placed, its descriptor
//! (`GridMedium`: the scene-to-grid map, the sizes and where its numbers start), and in one
//! array every grid's densities followed by its blocks' majorants.

use super::params::placed_grids;
use crate::kernel::types::GridMedium;
use crate::scene::grid::MAJORANT_BLOCK;
use crate::scene::medium::Media;

/// The descriptors and the numbers of the grids the kernel holds, in `placed_grids` order.
pub(super) fn kernel_grids(media: &Media) -> (Vec<GridMedium>, Vec<f32>) {
    let mut grids = Vec::new();
    let mut voxels = Vec::new();
    for m in placed_grids(media) {
        let placed = media.list[m as usize]
            .grid
            .as_ref()
            .expect("placed_grids has grids only");
        let grid = &placed.grid;
        let to_grid = (placed.placement * grid.grid_to_object).inverse();
        let row = |r: usize| {
            let r = to_grid.row(r);
            [r.x, r.y, r.z, r.w]
        };
        let start = voxels.len() as u32;
        voxels.extend_from_slice(&grid.density);
        let majorants = voxels.len() as u32;
        voxels.extend(grid.majorants());
        grids.push(GridMedium {
            to_grid_x: row(0),
            to_grid_y: row(1),
            to_grid_z: row(2),
            dims: grid.dims,
            voxels: start,
            blocks: grid.block_dims(),
            majorants,
            block: MAJORANT_BLOCK,
            _pad: [0; 3],
        });
    }
    (grids, voxels)
}
