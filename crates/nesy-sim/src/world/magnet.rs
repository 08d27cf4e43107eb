//! The magnetic hook's magnet: a pull on every piece of a fine-grained object (screws)
//! within [`MAGNET_RADIUS`] of the magnet's centre, applied as an impulse before every
//! physics substep. Gathering is what this force does to the pieces: near the magnet they
//! slide or jump to it and stay against it (carried along when the hook moves); beyond the
//! radius nothing acts on them.
//!
//! A stated radius with a constant pull inside it is a simplification of a real magnet's
//! field, whose force falls off steeply with distance: it makes "within reach of the magnet"
//! a property the scene and the tests can state.

use rapier3d::prelude::Vector;

use crate::scene::ObjectKind;
use crate::world::objects::{self, nominal_size};
use crate::world::{CONTROL_DT, SUBSTEPS, Sim};

/// Distance (m) from the magnet's centre within which it pulls a piece.
pub const MAGNET_RADIUS: f64 = 0.05;
/// Acceleration (m/s²) the pull gives a piece: three times gravity, so a piece below the
/// magnet is lifted to it and one against it is held while the hook is carried.
pub const MAGNET_PULL: f64 = 3.0 * 9.81;

impl Sim {
    /// Every magnetic hook's part and the world position of its magnet's centre.
    pub fn magnets(&self) -> Vec<(usize, [f64; 3])> {
        self.parts
            .iter()
            .enumerate()
            .filter(|(_, p)| p.kind == ObjectKind::MagneticHook)
            .map(|(i, p)| {
                let spec = &self.scene.objects[p.object];
                let local = objects::magnet_centre(spec.size.unwrap_or_else(|| nominal_size(spec.kind)));
                let at = self.part_pose(i) * nalgebra::Point3::from(local);
                (i, [at.x, at.y, at.z])
            })
            .collect()
    }

    /// World positions of the magnets of every magnetic hook in the scene, in part order.
    pub fn magnet_centres(&self) -> Vec<[f64; 3]> {
        self.magnets().into_iter().map(|(_, centre)| centre).collect()
    }

    /// Gives every fine-grained piece within [`MAGNET_RADIUS`] of a magnet one substep's
    /// impulse toward it, and the hook the opposite impulse (a hook resting on the table
    /// is held by friction; a carried one is driven by the arm).
    pub(crate) fn apply_magnets(&mut self) {
        let magnets = self.magnets();
        if magnets.is_empty() {
            return;
        }
        let dt = CONTROL_DT / f64::from(SUBSTEPS);
        let mut reactions = vec![[0.0f64; 3]; magnets.len()];
        for part in self.parts.iter().filter(|p| p.kind.is_fine_grained()) {
            let body = &mut self.world.bodies[part.body];
            if !body.is_dynamic() {
                continue;
            }
            let centre = body.center_of_mass();
            let p = [f64::from(centre.x), f64::from(centre.y), f64::from(centre.z)];
            for ((_, m), reaction) in magnets.iter().zip(reactions.iter_mut()) {
                let d = [m[0] - p[0], m[1] - p[1], m[2] - p[2]];
                let distance = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if !(1e-6..=MAGNET_RADIUS).contains(&distance) {
                    continue;
                }
                let scale = f64::from(body.mass()) * MAGNET_PULL * dt / distance;
                let impulse = d.map(|v| v * scale);
                body.apply_impulse(
                    Vector::new(impulse[0] as f32, impulse[1] as f32, impulse[2] as f32),
                    true,
                );
                for (r, v) in reaction.iter_mut().zip(impulse) {
                    *r -= v;
                }
            }
        }
        for ((hook, _), r) in magnets.iter().zip(reactions) {
            let body = &mut self.world.bodies[self.parts[*hook].body];
            if body.is_dynamic() && r.iter().any(|v| *v != 0.0) {
                body.apply_impulse(Vector::new(r[0] as f32, r[1] as f32, r[2] as f32), true);
            }
        }
    }
}
