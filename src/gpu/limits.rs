//! The device's buffer limits, checked before anything is uploaded: a scene too large for the
//! device is bad input (exit 2) with the limit and the scene's need in the message, not a raw
//! wgpu error after the upload. Every GPU buffer a renderer creates goes through
//! [`check_buffers`] (scene arrays, accumulators, and acceleration structures alike).

use crate::error::InputError;

/// How a buffer is bound, which decides the limit its binding must fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BufferBinding {
    Storage,
    Uniform,
    /// Not bound to a shader (copies and readback): only the buffer size limit applies.
    Unbound,
}

impl From<wgpu::BufferBindingType> for BufferBinding {
    fn from(ty: wgpu::BufferBindingType) -> Self {
        match ty {
            wgpu::BufferBindingType::Uniform => BufferBinding::Uniform,
            wgpu::BufferBindingType::Storage { .. } => BufferBinding::Storage,
        }
    }
}

/// A buffer a renderer is about to create: what it holds, its size, how it is bound.
#[derive(Clone, Copy, Debug)]
pub struct BufferNeed<'a> {
    pub label: &'a str,
    pub bytes: u64,
    pub binding: BufferBinding,
}

impl<'a> BufferNeed<'a> {
    pub fn new(label: &'a str, bytes: u64, binding: impl Into<BufferBinding>) -> Self {
        BufferNeed {
            label,
            bytes,
            binding: binding.into(),
        }
    }
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / (1u64 << 20) as f64)
}

/// Checks every buffer against the device's `max_buffer_size` and the binding limit of its
/// kind (`max_storage_buffer_binding_size`, `max_uniform_buffer_binding_size`). The error
/// names the buffer, the scene's need and the limit.
pub fn check_buffers(limits: &wgpu::Limits, needs: &[BufferNeed]) -> Result<(), InputError> {
    for need in needs {
        let binding_limit = match need.binding {
            BufferBinding::Storage => Some((
                "max_storage_buffer_binding_size",
                limits.max_storage_buffer_binding_size,
            )),
            BufferBinding::Uniform => Some((
                "max_uniform_buffer_binding_size",
                limits.max_uniform_buffer_binding_size,
            )),
            BufferBinding::Unbound => None,
        };
        for (name, limit) in binding_limit
            .into_iter()
            .chain([("max_buffer_size", limits.max_buffer_size)])
        {
            if need.bytes > limit {
                return Err(InputError(format!(
                    "the scene is too large for this GPU: its {} buffer needs {} bytes ({}), \
                     but the device's {name} is {limit} bytes ({})",
                    need.label,
                    need.bytes,
                    mib(need.bytes),
                    mib(limit)
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_buffer_over_a_limit_is_named_with_the_limit() {
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: 128 << 20,
            max_buffer_size: 256 << 20,
            ..Default::default()
        };
        let fits = BufferNeed::new("quads", 128 << 20, BufferBinding::Storage);
        assert!(check_buffers(&limits, &[fits]).is_ok());
        let quads = BufferNeed::new("quads", 144_000_000, BufferBinding::Storage);
        let e = check_buffers(&limits, &[fits, quads]).unwrap_err().0;
        assert!(e.contains("quads buffer needs 144000000 bytes"), "{e}");
        assert!(
            e.contains("max_storage_buffer_binding_size is 134217728"),
            "{e}"
        );
        let readback = BufferNeed::new("readback", 300 << 20, BufferBinding::Unbound);
        let e = check_buffers(&limits, &[readback]).unwrap_err().0;
        assert!(e.contains("max_buffer_size"), "{e}");
    }
}
