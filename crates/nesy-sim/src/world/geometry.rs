//! Axis-aligned boxes in f64 and conversions between the kinematics' nalgebra types and
//! Rapier's glam types.

use nalgebra::{Quaternion, Translation3, UnitQuaternion, Vector3};
use rapier3d::prelude::{Pose, Rotation, Vector};

use crate::robot::kinematics::Iso;

/// A world-frame axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

impl Aabb {
    /// An empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };

    /// Smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: std::array::from_fn(|i| self.min[i].min(other.min[i])),
            max: std::array::from_fn(|i| self.max[i].max(other.max[i])),
        }
    }

    /// Centre.
    pub fn centre(&self) -> [f64; 3] {
        std::array::from_fn(|i| 0.5 * (self.min[i] + self.max[i]))
    }

    /// Extents.
    pub fn size(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.max[i] - self.min[i])
    }

    /// Volume.
    pub fn volume(&self) -> f64 {
        let s = self.size();
        s[0].max(0.0) * s[1].max(0.0) * s[2].max(0.0)
    }

    /// The box grown by `lo` (usually negative) at the lower corner and `hi` at the upper.
    pub fn padded(&self, lo: [f64; 3], hi: [f64; 3]) -> Aabb {
        Aabb {
            min: std::array::from_fn(|i| self.min[i] + lo[i]),
            max: std::array::from_fn(|i| self.max[i] + hi[i]),
        }
    }

    /// True if `other` lies entirely inside.
    pub fn contains_box(&self, other: &Aabb) -> bool {
        (0..3).all(|i| other.min[i] >= self.min[i] && other.max[i] <= self.max[i])
    }

    /// True if the point lies inside (closed).
    pub fn contains_point(&self, p: [f64; 3]) -> bool {
        (0..3).all(|i| p[i] >= self.min[i] && p[i] <= self.max[i])
    }

    /// Overlap length along axis `i` (negative when apart).
    pub fn overlap(&self, other: &Aabb, i: usize) -> f64 {
        self.max[i].min(other.max[i]) - self.min[i].max(other.min[i])
    }

    /// True if the xy footprints overlap by more than `margin` on both axes.
    pub fn overlaps_xy(&self, other: &Aabb, margin: f64) -> bool {
        self.overlap(other, 0) > margin && self.overlap(other, 1) > margin
    }

    /// True if the segment from `a` to `b` meets the box (slab test).
    pub fn intersects_segment(&self, a: [f64; 3], b: [f64; 3]) -> bool {
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for i in 0..3 {
            let d = b[i] - a[i];
            if d.abs() < 1e-12 {
                if a[i] < self.min[i] || a[i] > self.max[i] {
                    return false;
                }
            } else {
                let (mut ta, mut tb) = ((self.min[i] - a[i]) / d, (self.max[i] - a[i]) / d);
                if ta > tb {
                    std::mem::swap(&mut ta, &mut tb);
                }
                t0 = t0.max(ta);
                t1 = t1.min(tb);
                if t0 > t1 {
                    return false;
                }
            }
        }
        true
    }

    /// From a parry box.
    pub fn from_parry(aabb: &rapier3d::parry::bounding_volume::Aabb) -> Aabb {
        Aabb {
            min: [aabb.mins.x as f64, aabb.mins.y as f64, aabb.mins.z as f64],
            max: [aabb.maxs.x as f64, aabb.maxs.y as f64, aabb.maxs.z as f64],
        }
    }
}

/// nalgebra isometry to a Rapier pose.
pub fn iso_to_pose(iso: &Iso) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x as f32, t.y as f32, t.z as f32),
        Rotation::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize(),
    )
}

/// Rapier pose to a nalgebra isometry.
pub fn pose_to_iso(pose: &Pose) -> Iso {
    let t = pose.translation;
    let r = pose.rotation;
    Iso::from_parts(
        Translation3::new(t.x as f64, t.y as f64, t.z as f64),
        UnitQuaternion::from_quaternion(Quaternion::new(r.w as f64, r.x as f64, r.y as f64, r.z as f64)),
    )
}

/// A glam vector as an f64 array.
pub fn vec_to_array(v: Vector) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// An f64 array as an nalgebra vector.
pub fn array_to_na(a: [f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

/// Yaw (rotation about z) of a rotation, from its x axis.
pub fn yaw_of(rotation: &UnitQuaternion<f64>) -> f64 {
    let x = rotation * Vector3::x();
    x.y.atan2(x.x)
}

/// Wraps an angle to (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let two_pi = std::f64::consts::TAU;
    let mut r = a % two_pi;
    if r <= -std::f64::consts::PI {
        r += two_pi;
    } else if r > std::f64::consts::PI {
        r -= two_pi;
    }
    r
}
