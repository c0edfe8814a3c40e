//! lavapipe before Mesa 23.1 recompiles a shader on every bind and never frees the old code.
//!
//! lavapipe "inlines" uniforms: when a shader's loop bound or branch condition is a value
//! loaded from a uniform buffer at a constant offset, it compiles a copy of the shader with
//! that value as a constant. Mesa 22.3 (Debian 12's default) does this again at every bind of
//! the pipeline, with no cache of the variants, and keeps each compiled copy: a glint render
//! binds the kernel once per dispatch, so a mesh render grew by ~33 MB/s (1.3 MB per dispatch)
//! and ran at half speed, and the viewer (kernel and display pass, every frame) by ~40 MB/s
//! until LLVM ran out of code memory. Later Mesa caches the variants by value.
//!
//! So on those drivers glint reads its per-dispatch parameters from a storage buffer, whose
//! values are never inlined. Elsewhere they stay in a uniform buffer, which llvmpipe loads
//! faster (the plain Cornell box was ~10% slower on Mesa 25 with them in storage).

use crate::kernel::source::ParamsBinding;

/// The binding of the kernel's `Params` for a device: storage where the driver would recompile
/// the kernel at every dispatch.
pub fn params_binding_for(info: &wgpu::AdapterInfo) -> ParamsBinding {
    if recompiles_inlined_uniforms(info) {
        ParamsBinding::Storage
    } else {
        ParamsBinding::Uniform
    }
}

/// Whether the adapter is lavapipe from a Mesa older than 23.1, from its driver information
/// (e.g. "Mesa 22.3.6 (LLVM 15.0.6)").
pub fn recompiles_inlined_uniforms(info: &wgpu::AdapterInfo) -> bool {
    let lavapipe = info.name.to_lowercase().contains("llvmpipe")
        || info.driver.to_lowercase().contains("llvmpipe");
    lavapipe && mesa_version(&info.driver_info).is_some_and(|v| v < (23, 1))
}

/// (major, minor) from a driver string holding "Mesa X.Y…".
pub fn mesa_version(driver_info: &str) -> Option<(u32, u32)> {
    let rest = &driver_info[driver_info.find("Mesa ")? + 5..];
    let mut parts = rest.split(|c: char| !c.is_ascii_digit());
    let major = parts.next()?.parse().ok()?;
    let minor = parts.next()?.parse().ok()?;
    Some((major, minor))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lavapipe(driver_info: &str) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            vendor: 0x10005,
            device: 0,
            device_type: wgpu::DeviceType::Cpu,
            device_pci_bus_id: String::new(),
            driver: "llvmpipe".into(),
            driver_info: driver_info.into(),
            backend: wgpu::Backend::Vulkan,
            subgroup_min_size: 8,
            subgroup_max_size: 8,
            transient_saves_memory: Some(false),
            limit_bucket: None,
        }
    }

    #[test]
    fn old_lavapipe_gets_its_params_from_storage() {
        assert_eq!(mesa_version("Mesa 22.3.6 (LLVM 15.0.6)"), Some((22, 3)));
        assert_eq!(
            mesa_version("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"),
            Some((25, 0))
        );
        assert_eq!(mesa_version("NVIDIA 560.35"), None);
        let binding = |info: &str| params_binding_for(&lavapipe(info));
        assert_eq!(binding("Mesa 22.3.6 (LLVM 15.0.6)"), ParamsBinding::Storage);
        assert_eq!(binding("Mesa 23.0.4"), ParamsBinding::Storage);
        assert_eq!(binding("Mesa 23.1.0"), ParamsBinding::Uniform);
        assert_eq!(
            binding("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"),
            ParamsBinding::Uniform
        );
        assert_eq!(binding(""), ParamsBinding::Uniform);
        let mut nvidia = lavapipe("NVIDIA 560.35");
        nvidia.name = "NVIDIA H200".into();
        nvidia.driver = "NVIDIA".into();
        assert_eq!(params_binding_for(&nvidia), ParamsBinding::Uniform);
    }
}
