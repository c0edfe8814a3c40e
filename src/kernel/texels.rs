//! How the kernel binds the images' texels (`KernelScene::texels`): one storage binding when
//! they fit the device's `max_storage_buffer_binding_size`, else windows of them over up to
//! [`MAX_TEXEL_WINDOWS`] bindings (shaders/textures/texels/). Why: five 2048² images (glTF's
//! DamagedHelmet) take 256 MiB as vec4<f32> texels, twice lavapipe's 128 MiB binding limit.
//! The CPU reads the one array either way; the GPU's windows are slices of it, so both read
//! the same texels.

use crate::error::InputError;

/// The most windows the kernel declares: binding 21 and [`EXTRA_WINDOW_BINDINGS`].
pub const MAX_TEXEL_WINDOWS: usize = 4;

/// Bindings of windows 1 to 3 (window 0 is `texels`, binding 21).
pub const EXTRA_WINDOW_BINDINGS: [u32; MAX_TEXEL_WINDOWS - 1] = [29, 30, 31];

/// Bytes of one texel (`vec4<f32>`).
pub const TEXEL_BYTES: u64 = 16;

const ONE_BINDING: &str = include_str!("../../shaders/textures/texels/one_binding.wgsl");
const WINDOWS: &str = include_str!("../../shaders/textures/texels/windows.wgsl");

/// Where the kernel reads texels from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelBinding {
    /// All in `texels` (binding 21): every scene whose texels fit one binding.
    One,
    /// Windows of `texels_per_window` texels (a power of two) at binding 21 and
    /// [`EXTRA_WINDOW_BINDINGS`].
    Windows { texels_per_window: u32 },
}

impl TexelBinding {
    /// The binding for `texel_count` texels when one binding holds at most `window_bytes`
    /// bytes (the device's limit, or a smaller one tests force): one binding when they fit,
    /// windows of the largest power of two of texels that fits otherwise, and bad input when
    /// even [`MAX_TEXEL_WINDOWS`] windows cannot hold them.
    pub fn plan(texel_count: u64, window_bytes: u64) -> Result<TexelBinding, InputError> {
        let bytes = texel_count * TEXEL_BYTES;
        if bytes <= window_bytes {
            return Ok(TexelBinding::One);
        }
        let fit = (window_bytes / TEXEL_BYTES).min(u32::MAX as u64);
        // A power of two, so the kernel's division is a shift.
        let texels_per_window = if fit == 0 {
            0
        } else {
            1u64 << (63 - fit.leading_zeros())
        };
        if texels_per_window == 0
            || texel_count.div_ceil(texels_per_window) > MAX_TEXEL_WINDOWS as u64
        {
            return Err(InputError(format!(
                "the scene is too large for this GPU: its texture texels need {bytes} bytes \
                 ({}), more than the {MAX_TEXEL_WINDOWS} storage bindings the kernel splits them \
                 over hold: each holds {} bytes ({}) of texels, as the device's \
                 max_storage_buffer_binding_size is {window_bytes} bytes ({})",
                mib(bytes),
                texels_per_window * TEXEL_BYTES,
                mib(texels_per_window * TEXEL_BYTES),
                mib(window_bytes)
            )));
        }
        Ok(TexelBinding::Windows {
            texels_per_window: texels_per_window as u32,
        })
    }

    /// The texel ranges of each of [`MAX_TEXEL_WINDOWS`] bindings (`texels` first), for
    /// `texel_count` texels: the whole array in the first with one binding. Empty ranges are
    /// bound to a placeholder.
    pub fn windows(&self, texel_count: usize) -> [std::ops::Range<usize>; MAX_TEXEL_WINDOWS] {
        let per = match self {
            TexelBinding::One => texel_count.max(1),
            TexelBinding::Windows { texels_per_window } => *texels_per_window as usize,
        };
        std::array::from_fn(|k| (k * per).min(texel_count)..((k + 1) * per).min(texel_count))
    }

    /// Whether the kernel binds the extra windows.
    pub fn is_split(&self) -> bool {
        matches!(self, TexelBinding::Windows { .. })
    }

    /// The WGSL of the texel fetch `texel_at`, as a named kernel part.
    pub fn part(&self) -> (&'static str, String) {
        match self {
            TexelBinding::One => ("texels/one_binding.wgsl", ONE_BINDING.to_string()),
            TexelBinding::Windows { texels_per_window } => (
                "texels/windows.wgsl",
                format!("const TEXELS_PER_WINDOW: u32 = {texels_per_window}u;\n{WINDOWS}"),
            ),
        }
    }
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / (1u64 << 20) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texels_that_fit_one_binding_keep_it() {
        assert_eq!(
            TexelBinding::plan(0, 128 << 20).ok(),
            Some(TexelBinding::One)
        );
        assert_eq!(
            TexelBinding::plan(8 << 20, 128 << 20).ok(),
            Some(TexelBinding::One)
        );
    }

    #[test]
    fn larger_texels_split_into_power_of_two_windows() {
        // The helmet: five 2048² images, 256 MiB, under lavapipe's 128 MiB.
        let helmet = 5 * 2048 * 2048;
        assert_eq!(
            TexelBinding::plan(helmet, 128 << 20).ok(),
            Some(TexelBinding::Windows {
                texels_per_window: 8 << 20
            })
        );
        // A limit that is not a power of two of texels rounds down.
        let binding = TexelBinding::plan(1000, 5000).unwrap();
        assert_eq!(
            binding,
            TexelBinding::Windows {
                texels_per_window: 256
            }
        );
        let w = binding.windows(1000);
        assert_eq!(w, [0..256, 256..512, 512..768, 768..1000]);
        assert_eq!(
            TexelBinding::One.windows(10),
            [0..10, 10..10, 10..10, 10..10]
        );
    }

    #[test]
    fn too_many_windows_is_bad_input_naming_the_sizes() {
        let e = TexelBinding::plan(1025, 4096).unwrap_err().0;
        assert!(e.contains("texture texels need 16400 bytes"), "{e}");
        assert!(
            e.contains("max_storage_buffer_binding_size is 4096 bytes"),
            "{e}"
        );
        assert!(TexelBinding::plan(1024, 4096).is_ok());
        assert!(TexelBinding::plan(1, 8).is_err());
    }
}
