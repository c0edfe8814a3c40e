//! Vertex tangents for normal maps: the file's own (glTF's TANGENT), or MikkTSpace's where it
//! gives none, as glTF requires (the `mikktspace` crate, the reference implementation's port).

use super::Geometry;
use glam::{Mat3, Vec3, Vec4};

/// The tangents at each face's three corners, in the file's space: xyz along increasing u,
/// w the bitangent's sign (bitangent = w · normal × tangent, along increasing v; v is up in
/// glint as in glTF's normal-map convention). `None` when the geometry has no texture
/// coordinates or an index out of range (the caller reports those).
pub(super) fn corner_tangents(geometry: &Geometry) -> Option<Vec<[Vec4; 3]>> {
    let count = geometry.positions.len();
    if geometry.uvs.len() != count
        || geometry
            .indices
            .iter()
            .flatten()
            .any(|&i| i as usize >= count)
    {
        return None;
    }
    if geometry.tangents.len() == count {
        return Some(
            geometry
                .indices
                .iter()
                .map(|f| f.map(|i| geometry.tangents[i as usize]))
                .collect(),
        );
    }
    let mut mikk = Mikk {
        geometry,
        smooth: geometry.normals.len() == count && geometry.normals.iter().all(|n| n.is_finite()),
        out: vec![[Vec4::ZERO; 3]; geometry.indices.len()],
    };
    // False for geometry it cannot use (no faces): the tangents stay zero, and zero tangents
    // leave the interpolated normal as it is.
    mikktspace::generate_tangents(&mut mikk);
    Some(mikk.out)
}

/// A tangent taken to the scene's space by `matrix` (the linear part of the placement): its
/// direction, and its sign flipped where the placement mirrors (the bitangent, a cross product
/// of transformed vectors, would flip otherwise). Zero where it has no direction.
pub(super) fn placed_tangent(matrix: &Mat3, tangent: Vec4) -> Vec4 {
    let direction = (*matrix * tangent.truncate()).normalize_or_zero();
    let sign = if tangent.w < 0.0 { -1.0 } else { 1.0 } * matrix.determinant().signum();
    if direction == Vec3::ZERO || !direction.is_finite() {
        return Vec4::ZERO;
    }
    direction.extend(sign)
}

struct Mikk<'a> {
    geometry: &'a Geometry,
    /// Whether the vertex normals are usable (else each face's own normal).
    smooth: bool,
    out: Vec<[Vec4; 3]>,
}

impl Mikk<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.geometry.indices[face][vert] as usize
    }
}

impl mikktspace::Geometry for Mikk<'_> {
    fn num_faces(&self) -> usize {
        self.geometry.indices.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.geometry.positions[self.vertex(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        if self.smooth {
            return self.geometry.normals[self.vertex(face, vert)].to_array();
        }
        let [a, b, c] = self.geometry.indices[face].map(|i| self.geometry.positions[i as usize]);
        (b - a).cross(c - a).normalize_or_zero().to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.geometry.uvs[self.vertex(face, vert)].to_array()
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        self.out[face][vert] = Vec4::from(tangent);
    }
}
