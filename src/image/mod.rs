//! What a render becomes: images in files (PNG, EXR: `output`), written atomically after every
//! output was checked up front (`atomic_write`, `output_check`), tone mapped for display
//! (`tonemap`), denoised with the auxiliary images a render gives (`denoise`, `aov`) and compared
//! (`compare`).

pub mod aov;
pub mod atomic_write;
pub mod compare;
pub mod denoise;
pub mod format;
pub mod output;
pub mod output_check;
pub mod tonemap;
