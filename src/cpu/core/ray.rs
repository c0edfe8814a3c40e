//! A ray: where it starts and where it goes (`dir` need not be unit length where a caller says so).

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}
