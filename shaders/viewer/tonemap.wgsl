// Tone mapping for the viewer's display pass: the GPU mirror of src/image/tonemap.rs (same curves,
// same constants, same names; tests/suite/viewer_display.rs checks the two agree). Linear radiance
// × 2^exposure → a display-linear value in [0, 1]; the caller sRGB-encodes it.

// Curve codes, as src/viewer/display.rs writes them into the uniform.
const TONEMAP_CLAMP: u32 = 0u;
const TONEMAP_ACES: u32 = 1u;
const TONEMAP_AGX: u32 = 2u;

fn narkowicz_aces(x: vec3<f32>) -> vec3<f32> {
    return (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
}

// WGSL matrices are column-major: these are the transposes of the Rust rows.
const AGX_INSET: mat3x3<f32> = mat3x3<f32>(
    vec3<f32>(0.84247906, 0.042328242, 0.042375655),
    vec3<f32>(0.0784336, 0.8784686, 0.0784336),
    vec3<f32>(0.079223745, 0.07916613, 0.879143),
);
const AGX_OUTSET: mat3x3<f32> = mat3x3<f32>(
    vec3<f32>(1.196879, -0.05289685, -0.052971635),
    vec3<f32>(-0.09802088, 1.1519031, -0.09804345),
    vec3<f32>(-0.09902974, -0.09896118, 1.1510737),
);
const AGX_MIN_EV: f32 = -12.47393;
const AGX_MAX_EV: f32 = 4.026069;

// The polynomial fit of AgX's default contrast sigmoid, on x in [0, 1].
fn agx_contrast(x: vec3<f32>) -> vec3<f32> {
    let x2 = x * x;
    let x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.00232;
}

fn agx(rgb: vec3<f32>) -> vec3<f32> {
    let inset = AGX_INSET * rgb;
    // log2 of 0 (or less) is −∞: the clamp takes it to the darkest value.
    let ev = select(vec3<f32>(AGX_MIN_EV), log2(inset), inset > vec3<f32>(0.0));
    let t = (clamp(ev, vec3<f32>(AGX_MIN_EV), vec3<f32>(AGX_MAX_EV)) - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV);
    let outset = clamp(AGX_OUTSET * agx_contrast(t), vec3<f32>(0.0), vec3<f32>(1.0));
    // pow(0, y) is exp2(y · log2 0): keep black out of it.
    return select(pow(outset, vec3<f32>(2.2)), vec3<f32>(0.0), outset <= vec3<f32>(0.0));
}

// DisplayTransform::apply: `scale` is 2^exposure. NaN shows as black.
fn tonemap_apply(rgb: vec3<f32>, scale: f32, curve: u32) -> vec3<f32> {
    // Past 1e9 every curve is flat at white; capping there keeps x² finite.
    let x = clamp(select(rgb * scale, vec3<f32>(0.0), rgb != rgb), vec3<f32>(0.0), vec3<f32>(1e9));
    var mapped = x;
    if curve == TONEMAP_ACES {
        mapped = narkowicz_aces(x);
    } else if curve == TONEMAP_AGX {
        mapped = agx(x);
    }
    return clamp(mapped, vec3<f32>(0.0), vec3<f32>(1.0));
}
