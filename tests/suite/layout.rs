//! The kernel is valid WGSL and matches the host: naga validates every kernel variant, and its
//! layouter checks that every Rust struct in src/kernel/types.rs has the WGSL struct's offsets and
//! size, that the uniform arrays are as large as what the host uploads, and that the texel
//! windows' bindings (29–31) are the host's. So the host and the kernel cannot drift apart.

use glint::kernel::source::{
    render_kernel_source, render_kernel_source_for, render_kernel_source_with_texels,
    ParamsBinding, RENDER_ENTRY_POINT, WORKGROUP_SIZE,
};
use glint::kernel::texels::{TexelBinding, EXTRA_WINDOW_BINDINGS, TEXEL_BYTES};
use glint::kernel::types::{
    BvhNode, BvhWideNode, Emitter, EnvironmentAlias, EnvironmentTexel, GridMedium, Instance, Light,
    LightTreeNode, Material, Medium, Params, Quad, Sphere, Texture, Triangle, TriangleColors,
    TriangleNormals, TriangleTangents, TriangleUvs,
};
use glint::kernel::variant::{KernelFeatures, KernelVariant, SceneBinding, SceneCounts};
use naga::proc::Layouter;
use std::mem::{offset_of, size_of};

fn parse_and_validate() -> naga::Module {
    validate_source(render_kernel_source())
}

fn validate_source(source: String) -> naga::Module {
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
    module
}

#[test]
fn kernel_validates_and_has_the_render_entry_point() {
    let module = parse_and_validate();
    let entry = module
        .entry_points
        .iter()
        .find(|e| e.name == RENDER_ENTRY_POINT)
        .expect("render entry point");
    assert_eq!(entry.stage, naga::ShaderStage::Compute);
    assert_eq!(
        entry.workgroup_size,
        [WORKGROUP_SIZE.0, WORKGROUP_SIZE.1, 1]
    );
}

/// Offsets of every member and the size of a WGSL struct, from naga's layouter.
fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL struct {name}"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct");
    };
    let fields = members
        .iter()
        .map(|m| (m.name.clone().unwrap(), m.offset))
        .collect();
    (fields, layouter[handle].size)
}

/// Asserts a Rust struct has the WGSL struct's size and, for every WGSL member, a field of the
/// same name at the same offset. Rust-only padding fields (leading `_`) are not in the WGSL.
macro_rules! assert_same_layout {
    ($module:expr, $rust:ty, $wgsl:literal, [$($field:ident),* $(,)?]) => {{
        let (wgsl_fields, wgsl_size) = wgsl_layout($module, $wgsl);
        let rust_fields: Vec<(String, u32)> =
            vec![$((stringify!($field).to_string(), offset_of!($rust, $field) as u32)),*];
        assert_eq!(rust_fields, wgsl_fields, "member offsets of {}", $wgsl);
        assert_eq!(size_of::<$rust>() as u32, wgsl_size, "size of {}", $wgsl);
    }};
}

#[test]
fn rust_structs_match_wgsl_layout() {
    let module = parse_and_validate();
    assert_same_layout!(
        &module,
        Params,
        "Params",
        [
            eye,
            width,
            forward,
            height,
            right,
            sample_start,
            up,
            sample_count,
            background,
            max_bounces,
            lens_right,
            focus_distance,
            lens_up,
            light_sampling,
            seed,
            sphere_count,
            quad_count,
            material_count,
            emitter_count,
            roulette_start,
            accumulated_samples,
            aovs,
            radiance_clamp,
            triangle_count,
            environment_width,
            environment_height,
            environment_cos,
            environment_sin,
            environment_light_probability,
            light_count,
            projection,
            sampler,
            integrator,
            splat_scale,
            scene_center,
            scene_radius,
            medium_count,
            global_medium,
            camera_medium,
            media,
            light_tree_nodes,
            light_tree_probability
        ]
    );
    assert_same_layout!(
        &module,
        LightTreeNode,
        "LightTreeNode",
        [
            lo,
            phi,
            hi,
            cos_theta_o,
            axis,
            cos_theta_e,
            child,
            primitive,
            index,
            two_sided
        ]
    );
    assert_same_layout!(
        &module,
        Medium,
        "Medium",
        [sigma_t, g, sigma_s, boundary, grid]
    );
    assert_same_layout!(
        &module,
        GridMedium,
        "GridMedium",
        [to_grid_x, to_grid_y, to_grid_z, dims, voxels, blocks, majorants, block]
    );
    assert_same_layout!(
        &module,
        Sphere,
        "Sphere",
        [center, radius, material, light_probability]
    );
    assert_same_layout!(
        &module,
        Quad,
        "Quad",
        [
            corner,
            material,
            edge_u,
            area,
            edge_v,
            plane_offset,
            normal,
            light_probability,
            u_dual,
            pad1,
            v_dual,
            pad2
        ]
    );
    assert_same_layout!(
        &module,
        Material,
        "Material",
        [
            albedo,
            kind,
            emission,
            alpha,
            ior,
            color_texture,
            roughness_texture,
            metallic,
            specular_color,
            specular,
            emission_texture,
            normal_texture,
            normal_scale,
            alpha_mode,
            opacity,
            alpha_cutoff,
            transmission,
            transmission_texture,
            attenuation_color,
            attenuation_distance,
            clearcoat,
            clearcoat_alpha,
            clearcoat_texture,
            clearcoat_roughness_texture,
            clearcoat_normal_texture,
            clearcoat_normal_scale,
            sheen_roughness,
            sheen_color_texture,
            sheen_color,
            sheen_roughness_texture
        ]
    );
    assert_same_layout!(
        &module,
        Emitter,
        "Emitter",
        [
            primitive,
            index,
            probability,
            alias_threshold,
            alias_primitive,
            alias_index,
            alias_probability,
            _pad
        ]
    );
    assert_same_layout!(
        &module,
        Triangle,
        "Triangle",
        [v0, material, v1, light_probability, v2, area]
    );
    assert_same_layout!(
        &module,
        TriangleNormals,
        "TriangleNormals",
        [n0, smooth_shading, n1, n2]
    );
    assert_same_layout!(&module, BvhNode, "BvhNode", [min, first, max, count]);
    assert_same_layout!(
        &module,
        Instance,
        "Instance",
        [
            to_world,
            to_object,
            blas_root,
            first_triangle,
            triangle_count,
            _pad
        ]
    );
    assert_same_layout!(
        &module,
        BvhWideNode,
        "BvhWideNode",
        [min_x, min_y, min_z, max_x, max_y, max_z, first, count]
    );
    assert_same_layout!(
        &module,
        Light,
        "Light",
        [
            position,
            kind,
            direction,
            light_probability,
            emitted,
            spot_scale,
            spot_offset,
            sun_one_minus_cos,
            _pad
        ]
    );
    assert_same_layout!(
        &module,
        Texture,
        "Texture",
        [
            kind,
            first_texel,
            width,
            height,
            color0,
            scale,
            color1,
            sampling,
            transform_u,
            uv_set,
            transform_v
        ]
    );
    assert_same_layout!(&module, TriangleUvs, "TriangleUvs", [uv0, uv1, uv2]);
    assert_same_layout!(&module, TriangleTangents, "TriangleTangents", [t0, t1, t2]);
    assert_same_layout!(&module, TriangleColors, "TriangleColors", [c0, c1, c2]);
    // Ten vec4s: glTF's emissive and normal textures took the fifth, alpha and transmission
    // the sixth, volume attenuation the seventh, clearcoat the eighth and part of the ninth,
    // sheen the rest (a uniform-bound scene's materials stay far below the uniform limit).
    assert_eq!(size_of::<Material>(), 160, "Material stays 160 bytes");
    assert_same_layout!(
        &module,
        EnvironmentTexel,
        "EnvironmentTexel",
        [radiance, pdf]
    );
    assert_same_layout!(
        &module,
        EnvironmentAlias,
        "EnvironmentAlias",
        [threshold, alias_texel]
    );
}

/// The kernel's constants that mirror the host's: material kinds, alpha modes, projections,
/// and the sizes and offsets of the energy tables it indexes.
#[test]
fn wgsl_constants_match_the_hosts() {
    let module = parse_and_validate();
    let constant = |name: &str| {
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no WGSL constant {name}"));
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("{name} is {e:?}"),
        }
    };
    use glint::kernel::types as t;
    use glint::tables::clearcoat as c;
    use glint::tables::ggx as g;
    // Bidirectional path tracing's (in the kernel with every feature).
    use glint::cpu::integrator::bdpt::vertex as v;
    use glint::cpu::integrator::bdpt::walk as w;
    use glint::cpu::lights::emission as e;
    for (name, value) in [
        ("MATERIAL_DIFFUSE", t::MATERIAL_DIFFUSE),
        ("MATERIAL_SPECULAR", t::MATERIAL_SPECULAR),
        ("MATERIAL_METAL", t::MATERIAL_METAL),
        ("MATERIAL_DIELECTRIC", t::MATERIAL_DIELECTRIC),
        ("MATERIAL_PBR", t::MATERIAL_PBR),
        ("MATERIAL_UNLIT", t::MATERIAL_UNLIT),
        ("ALPHA_OPAQUE", t::ALPHA_OPAQUE),
        ("ALPHA_MASK", t::ALPHA_MASK),
        ("ALPHA_BLEND", t::ALPHA_BLEND),
        ("PROJECTION_PERSPECTIVE", t::PROJECTION_PERSPECTIVE),
        ("PROJECTION_ORTHOGRAPHIC", t::PROJECTION_ORTHOGRAPHIC),
        ("WIDE_EMPTY_CHILD", t::WIDE_EMPTY_CHILD),
        ("GGX_ENERGY_SIZE", g::GGX_ENERGY_SIZE as u32),
        ("GGX_ENERGY_OFFSET_A", g::OFFSET_A as u32),
        ("GGX_ENERGY_OFFSET_B", g::OFFSET_B as u32),
        ("GGX_ENERGY_OFFSET_A_AVERAGE", g::OFFSET_A_AVERAGE as u32),
        ("GGX_ENERGY_OFFSET_B_AVERAGE", g::OFFSET_B_AVERAGE as u32),
        ("GGX_ENERGY_OFFSET_AA_AVERAGE", g::OFFSET_AA_AVERAGE as u32),
        ("GGX_ENERGY_OFFSET_AB_AVERAGE", g::OFFSET_AB_AVERAGE as u32),
        ("GGX_ENERGY_OFFSET_BB_AVERAGE", g::OFFSET_BB_AVERAGE as u32),
        (
            "SHEEN_ENERGY_SIZE",
            glint::tables::sheen::SHEEN_ENERGY_SIZE as u32,
        ),
        ("CLEARCOAT_ENERGY_SIZE", c::CLEARCOAT_ENERGY_SIZE as u32),
        ("CLEARCOAT_ENERGY_PART", c::CLEARCOAT_ENERGY_PART as u32),
        ("INTEGRATOR_PATH", t::INTEGRATOR_PATH),
        ("INTEGRATOR_BDPT", t::INTEGRATOR_BDPT),
        ("EMITTER_AREA", e::EMITTER_AREA),
        ("EMITTER_POINT", e::EMITTER_POINT),
        ("EMITTER_INFINITE", e::EMITTER_INFINITE),
        ("EMITTER_DELTA_DIRECTION", e::EMITTER_DELTA_DIRECTION),
        ("VERTEX_CAMERA", v::VERTEX_CAMERA),
        ("VERTEX_LIGHT", v::VERTEX_LIGHT),
        ("VERTEX_SURFACE", v::VERTEX_SURFACE),
        ("VERTEX_MEDIUM", v::VERTEX_MEDIUM),
        (
            "CONNECTION_TRACKING",
            glint::cpu::integrator::bdpt::connect::CONNECTION_TRACKING,
        ),
        ("BDPT_MAX_BOUNCES", w::BDPT_MAX_BOUNCES),
        ("CAMERA_VERTICES", w::CAMERA_VERTICES as u32),
        ("LIGHT_VERTICES", w::LIGHT_VERTICES as u32),
        ("LIGHT_SUBPATH", w::LIGHT_SUBPATH),
        ("LIGHT_SEGMENTS", w::LIGHT_SEGMENTS),
        ("CONNECTION_SEGMENTS", w::CONNECTION_SEGMENTS),
    ] {
        assert_eq!(constant(name), value, "{name}");
    }
}

/// The uniform-buffer kernel validates for any counts, empty arrays included, and declares
/// each array with exactly as many bytes as the host uploads (at least one element).
#[test]
fn uniform_scene_kernel_declares_the_uploaded_sizes() {
    for counts in [
        SceneCounts {
            spheres: 0,
            quads: 0,
            materials: 1,
            emitters: 0,
        },
        SceneCounts {
            spheres: 2,
            quads: 6,
            materials: 5,
            emitters: 1,
        },
        SceneCounts {
            spheres: 1,
            quads: 682,
            materials: 3,
            emitters: 2,
        },
    ] {
        let module = validate_source(render_kernel_source_for(KernelVariant {
            binding: SceneBinding::Uniform(counts),
            features: KernelFeatures::ALL,
        }));
        let mut layouter = Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let binding_size = |binding: u32| {
            let (_, var) = module
                .global_variables
                .iter()
                .find(|(_, v)| v.binding.as_ref().is_some_and(|b| b.binding == binding))
                .unwrap_or_else(|| panic!("no binding {binding}"));
            assert_eq!(var.space, naga::AddressSpace::Uniform, "binding {binding}");
            layouter[var.ty].size as usize
        };
        let uploaded = |count: u32, size: usize| count.max(1) as usize * size;
        assert_eq!(
            binding_size(1),
            uploaded(counts.spheres, size_of::<Sphere>())
        );
        assert_eq!(binding_size(2), uploaded(counts.quads, size_of::<Quad>()));
        assert_eq!(
            binding_size(3),
            uploaded(counts.materials, size_of::<Material>())
        );
        assert_eq!(
            binding_size(6),
            uploaded(counts.emitters, size_of::<Emitter>())
        );
        assert_eq!(
            counts.largest_uniform_buffer() as usize,
            [
                binding_size(1),
                binding_size(2),
                binding_size(3),
                binding_size(6)
            ]
            .into_iter()
            .max()
            .unwrap()
        );
    }
}

/// A kernel without media carries none of the media's code, only media/no_media.wgsl's stubs
/// (of the phase function too: bidirectional's vertices name it):
/// behind a constant `false`, lavapipe still translated and inlined it for every kernel it built
/// (docs/src/performance/history/2026-12-04-media-free-cost.md).
#[test]
fn kernels_without_media_carry_only_the_media_stubs() {
    let source = |media| {
        render_kernel_source_for(KernelVariant {
            binding: SceneBinding::Storage,
            features: KernelFeatures {
                media,
                ..KernelFeatures::ALL
            },
        })
    };
    let (with, without) = (source(true), source(false));
    for part in [
        "// ---- media/phase.wgsl",
        "// ---- media/medium.wgsl",
        "// ---- integrator/path_media.wgsl",
        "fn sample_free_flight(",
        "fn segment_transmittance(",
        "fn ray_end_distance(",
    ] {
        assert!(with.contains(part), "{part} missing with media");
        assert!(!without.contains(part), "{part} present without media");
    }
    assert!(without.contains("// ---- media/no_media.wgsl"));
    assert!(!with.contains("// ---- media/no_media.wgsl"));
    assert!(!without.contains("// ---- media/no_grid.wgsl"));
}

/// Kernels of scenes whose media are all homogeneous carry the grid stub, not the tracking.
#[test]
fn kernels_without_grid_media_carry_only_the_grid_stub() {
    let source = |grid_media| {
        render_kernel_source_for(KernelVariant {
            binding: SceneBinding::Storage,
            features: KernelFeatures {
                grid_media,
                ..KernelFeatures::ALL
            },
        })
    };
    let (with, without) = (source(true), source(false));
    for part in [
        "// ---- media/grid.wgsl",
        "fn block_walk(",
        "var<storage, read> grid_voxels",
    ] {
        assert!(with.contains(part), "{part} missing with grid media");
        assert!(!without.contains(part), "{part} present without grid media");
    }
    assert!(without.contains("// ---- media/no_grid.wgsl"));
    assert!(!with.contains("// ---- media/no_grid.wgsl"));
}

/// Kernels of scenes picking emitters by power carry the light tree's stubs, not the tree nor
/// its bindings.
#[test]
fn kernels_without_a_light_tree_carry_only_its_stubs() {
    let source = |light_tree| {
        render_kernel_source_for(KernelVariant {
            binding: SceneBinding::Storage,
            features: KernelFeatures {
                light_tree,
                ..KernelFeatures::ALL
            },
        })
    };
    let (with, without) = (source(true), source(false));
    for part in [
        "// ---- lights/light_tree.wgsl",
        "fn node_importance(",
        "var<storage, read> light_tree_nodes",
    ] {
        assert!(with.contains(part), "{part} missing with the tree");
        assert!(!without.contains(part), "{part} present without the tree");
    }
    assert!(without.contains("// ---- lights/no_light_tree.wgsl"));
    assert!(!with.contains("// ---- lights/no_light_tree.wgsl"));
}

/// Every combination of compiled-out features gives a valid kernel, in every binding.
#[test]
fn every_feature_combination_validates() {
    let counts = SceneCounts {
        spheres: 2,
        quads: 6,
        materials: 5,
        emitters: 1,
    };
    // The lights' two flags vary with the others (every pattern of those nine would take four
    // times as long): each is on in half the combinations, in no fixed relation to any flag.
    for bits in 0..512u32 {
        let features = KernelFeatures {
            light_sampling: bits & 1 != 0,
            sphere_emitters: bits & 2 != 0,
            quad_emitters: bits & 4 != 0,
            metal: bits & 8 != 0,
            dielectric: bits & 16 != 0,
            aovs: bits & 32 != 0,
            triangle_emitters: bits & 64 != 0,
            environment: bits & 128 != 0,
            textures: bits & 256 != 0,
            lights: bits.count_ones() % 2 == 1,
            sun_disks: (bits * 7 / 3) % 2 == 1,
            // Not another bit (that would double the test's time): a function of the bits that
            // meets every other feature both on and off.
            pbr: (bits.count_ones() / 2) % 2 == 1,
            // Likewise: on with pbr in some combinations and without it in others.
            transmission: (bits / 3) % 2 == 1,
            // Likewise, the coat and the sheen, each with and without pbr and the other.
            clearcoat: (bits / 7) % 2 == 1,
            sheen: (bits / 11) % 2 == 1,
            volume: (bits / 5) % 2 == 1,
            // Likewise: on in half the combinations, with and without textures and triangles.
            alpha: (bits * 5 / 3) % 2 == 1,
            // Likewise, with and without alpha and textures.
            vertex_colors: (bits * 11 / 7) % 2 == 1,
            // Likewise, with and without textures.
            texcoord1: (bits * 13 / 9) % 2 == 1,
            // Likewise, with and without alpha.
            instances: (bits * 17 / 11) % 2 == 1,
            // Likewise, with and without light sampling, lights and dielectrics.
            media: (bits * 19 / 13) % 2 == 1,
            // Likewise, with and without media (without them it is compiled out either way).
            grid_media: (bits * 29 / 19) % 2 == 1,
            // Likewise, with and without lights, the environment, textures and triangles.
            bdpt: (bits * 23 / 17) % 2 == 1,
            // Likewise, with and without each kind of emitter and lights.
            light_tree: (bits * 31 / 23) % 2 == 1,
        };
        for binding in [
            SceneBinding::Storage,
            SceneBinding::Uniform(counts),
            SceneBinding::Bvh {
                uniform_nodes: 2048,
                stack_size: 64,
            },
            SceneBinding::WideBvh {
                uniform_nodes: 512,
                stack_size: 200,
            },
        ] {
            validate_source(render_kernel_source_for(KernelVariant {
                binding,
                features,
            }));
        }
    }
}

/// The hardware traversal's variant (ray queries) is valid WGSL with every feature and with
/// none, and starts by enabling ray queries; no other variant mentions them, so each compiles
/// on a device without them.
#[test]
fn hardware_variant_validates_and_only_it_uses_ray_queries() {
    let none = KernelFeatures {
        light_sampling: false,
        sphere_emitters: false,
        quad_emitters: false,
        triangle_emitters: false,
        metal: false,
        dielectric: false,
        pbr: false,
        transmission: false,
        clearcoat: false,
        sheen: false,
        volume: false,
        aovs: false,
        textures: false,
        environment: false,
        lights: false,
        sun_disks: false,
        alpha: false,
        vertex_colors: false,
        texcoord1: false,
        instances: false,
        media: false,
        grid_media: false,
        bdpt: false,
        light_tree: false,
    };
    for features in [KernelFeatures::ALL, none] {
        let source = render_kernel_source_for(KernelVariant {
            binding: SceneBinding::Hardware,
            features,
        });
        assert!(source.starts_with("enable wgpu_ray_query;"));
        validate_source(source);
        for binding in [
            SceneBinding::Storage,
            SceneBinding::Bvh {
                uniform_nodes: 1,
                stack_size: 8,
            },
        ] {
            let source = render_kernel_source_for(KernelVariant { binding, features });
            assert!(!source.contains("rayQuery") && !source.contains("wgpu_ray_query"));
        }
    }
}

/// The storage bindings of `module`'s texel windows: (binding, element bytes) of every global
/// bound at 21 or at one of [`EXTRA_WINDOW_BINDINGS`].
fn texel_window_bindings(module: &naga::Module) -> Vec<(u32, u32)> {
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let mut out: Vec<_> = module
        .global_variables
        .iter()
        .filter_map(|(_, v)| {
            let binding = v.binding.as_ref()?.binding;
            if binding != 21 && !EXTRA_WINDOW_BINDINGS.contains(&binding) {
                return None;
            }
            assert_eq!(
                v.space,
                naga::AddressSpace::Storage {
                    access: naga::StorageAccess::LOAD
                },
                "binding {binding}"
            );
            let naga::TypeInner::Array { base, .. } = module.types[v.ty].inner else {
                panic!("binding {binding} is not an array");
            };
            Some((binding, layouter[base].size))
        })
        .collect();
    out.sort();
    out
}

/// Split texels (src/kernel/texels.rs): the windowed kernel validates in every scene binding,
/// with textures on and off, and reads windows 2 to 4 at the bindings the host binds them to,
/// as read-only arrays of 16-byte texels like binding 21, with the host's window size; the
/// one-binding kernel declares none of them, so scenes that fit keep their kernel.
#[test]
fn texel_windows_are_bound_where_the_host_binds_them() {
    let counts = SceneCounts {
        spheres: 2,
        quads: 6,
        materials: 5,
        emitters: 1,
    };
    let split = TexelBinding::plan(1000, 4096).unwrap();
    let TexelBinding::Windows { texels_per_window } = split else {
        panic!("1000 texels fit 4096 bytes");
    };
    for binding in [
        SceneBinding::Storage,
        SceneBinding::Uniform(counts),
        SceneBinding::Bvh {
            uniform_nodes: 2048,
            stack_size: 64,
        },
        SceneBinding::WideBvh {
            uniform_nodes: 512,
            stack_size: 200,
        },
    ] {
        for textures in [true, false] {
            let variant = KernelVariant {
                binding,
                features: KernelFeatures {
                    textures,
                    ..KernelFeatures::ALL
                },
            };
            let source = render_kernel_source_with_texels(variant, ParamsBinding::Uniform, split);
            assert!(source.contains(&format!(
                "const TEXELS_PER_WINDOW: u32 = {texels_per_window}u;"
            )));
            let module = validate_source(source);
            let mut want = vec![(21, TEXEL_BYTES as u32)];
            want.extend(EXTRA_WINDOW_BINDINGS.map(|b| (b, TEXEL_BYTES as u32)));
            assert_eq!(texel_window_bindings(&module), want, "{binding:?}");
            let one = render_kernel_source_with_texels(
                variant,
                ParamsBinding::Uniform,
                TexelBinding::One,
            );
            assert_eq!(one, render_kernel_source_for(variant));
            assert!(!one.contains("TEXELS_PER_WINDOW"));
            assert_eq!(
                texel_window_bindings(&validate_source(one)),
                vec![(21, TEXEL_BYTES as u32)]
            );
        }
    }
}
