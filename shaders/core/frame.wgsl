// Local shading frames (mirror: src/cpu/core/frame.rs).

const PI: f32 = 3.14159265358979;

// Orthonormal basis around a unit n (Duff et al., "Building an Orthonormal Basis, Revisited", 2017).
fn basis_tangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
}

fn basis_bitangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, s + n.y * n.y * a, -n.y);
}

fn to_local(v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(v, basis_tangent(n)), dot(v, basis_bitangent(n)), dot(v, n));
}

fn from_local(v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return v.x * basis_tangent(n) + v.y * basis_bitangent(n) + v.z * n;
}
