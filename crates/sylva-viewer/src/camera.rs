//! The viewer's camera: an orbit about a target (drag to turn, scroll to zoom), and picking
//! the ground point under the cursor.

use glam::{Vec3, Vec4};
use sylva_core::scene::Scene;
use sylva_gpu::render::Camera;

/// An orbit camera: yaw and pitch about a target, at a distance.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Orbit {
    pub(crate) target: Vec3,
    pub(crate) yaw: f32,
    pub(crate) pitch: f32,
    pub(crate) distance: f32,
    pub(crate) fov_deg: f32,
}

impl Orbit {
    pub(crate) fn from_scene(s: &Scene) -> Self {
        let (eye, target) = (Vec3::from_array(s.camera.eye), Vec3::from_array(s.camera.target));
        let d = eye - target;
        let distance = d.length().max(0.5);
        Self {
            target,
            yaw: d.x.atan2(d.z),
            pitch: (d.y / distance).clamp(-1.0, 1.0).asin(),
            distance,
            fov_deg: s.camera.fov_deg,
        }
    }

    pub(crate) fn eye(&self) -> Vec3 {
        self.target
            + self.distance
                * Vec3::new(self.pitch.cos() * self.yaw.sin(), self.pitch.sin(), self.pitch.cos() * self.yaw.cos())
    }

    pub(crate) fn camera(&self) -> Camera {
        Camera { eye: self.eye(), target: self.target, fov_y_deg: self.fov_deg }
    }

    /// Where the ray through view point (u, v) (0…1 from the top left) meets the ground.
    pub(crate) fn ground_point(&self, u: f32, v: f32, aspect: f32) -> Option<Vec3> {
        let inv = self.camera().view_proj(aspect).inverse();
        let ndc = |z: f32| {
            let p = inv * Vec4::new(2.0 * u - 1.0, 1.0 - 2.0 * v, z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (ndc(0.0), ndc(1.0));
        let dir = far - near;
        (dir.y.abs() > 1e-6).then(|| near + dir * (-near.y / dir.y)).filter(|p| (p - near).dot(dir) > 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Picking: the view's centre lands on the target when it lies on the ground; a point
    /// lower in the view lands nearer the camera; the sky hits nothing.
    #[test]
    fn clicks_pick_the_ground_under_the_cursor() {
        let orbit = Orbit { target: Vec3::new(3.0, 0.0, -2.0), yaw: 0.7, pitch: 0.2, distance: 20.0, fov_deg: 45.0 };
        let centre = orbit.ground_point(0.5, 0.5, 16.0 / 9.0).unwrap();
        assert!(centre.distance(orbit.target) < 1e-3, "{centre}");
        let near = orbit.ground_point(0.5, 0.9, 16.0 / 9.0).unwrap();
        assert!(near.distance(orbit.eye()) < centre.distance(orbit.eye()));
        assert!(near.y.abs() < 1e-4);
        assert!(orbit.ground_point(0.5, 0.02, 16.0 / 9.0).is_none(), "the sky is not ground");
        // The scene's camera round-trips through the orbit.
        let mut scene = Scene::default_scene();
        scene.camera.eye = [4.0, 6.0, 30.0];
        scene.camera.target = [1.0, 2.0, 0.0];
        let o = Orbit::from_scene(&scene);
        assert!(o.eye().distance(Vec3::from_array(scene.camera.eye)) < 1e-4, "{}", o.eye());
    }
}
