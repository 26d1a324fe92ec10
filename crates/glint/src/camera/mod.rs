//! Cameras. Camera space looks along +z with +y up and +x to the *left* of the image
//! (Mitsuba's convention, so that `look_at` in XML and JSON scenes mean the same thing).

pub use crate::describe::{CropWindow, FovAxis, Projection};
use crate::math::{vec3, Ray, Transform, Vec3};
use crate::sampling::warp;

/// A perspective camera, optionally with a thin lens for depth of field, or an
/// orthographic one.
#[derive(Clone, Debug)]
pub struct Camera {
    pub to_world: Transform,
    pub width: u32,
    pub height: u32,
    /// Half-extent of the image plane at distance 1, along x and y.
    pub tan_half_x: f32,
    pub tan_half_y: f32,
    pub lens_radius: f32,
    pub focus_distance: f32,
    pub near_clip: f32,
    pub far_clip: f32,
    pub projection: Projection,
    /// The full image the rays are laid out over; `width` x `height` (the rendered image)
    /// is the part of it at `crop_offset` (all of it unless cropped).
    pub full_width: u32,
    pub full_height: u32,
    pub crop_offset: [u32; 2],
}

impl Camera {
    pub fn new(to_world: Transform, width: u32, height: u32, fov_degrees: f32, axis: FovAxis) -> Camera {
        let aspect = width as f32 / height as f32;
        let t = (fov_degrees.to_radians() * 0.5).tan();
        let (tx, ty) = match axis {
            FovAxis::X => (t, t / aspect),
            FovAxis::Y => (t * aspect, t),
            FovAxis::Diagonal => {
                let diag = (aspect * aspect + 1.0).sqrt();
                (t * aspect / diag, t / diag)
            }
            FovAxis::Smaller => {
                if aspect >= 1.0 {
                    (t * aspect, t)
                } else {
                    (t, t / aspect)
                }
            }
            FovAxis::Larger => {
                if aspect >= 1.0 {
                    (t, t / aspect)
                } else {
                    (t * aspect, t)
                }
            }
        };
        Camera {
            to_world,
            width,
            height,
            tan_half_x: tx,
            tan_half_y: ty,
            lens_radius: 0.0,
            focus_distance: 1.0,
            near_clip: 0.0,
            far_clip: f32::INFINITY,
            projection: Projection::Perspective,
            full_width: width,
            full_height: height,
            crop_offset: [0, 0],
        }
    }

    /// Renders only `crop` of the full image (its pixels are the full image's pixels).
    pub fn set_crop(&mut self, crop: CropWindow) {
        self.width = crop.width;
        self.height = crop.height;
        self.crop_offset = [crop.offset_x, crop.offset_y];
    }

    /// Changes the resolution keeping the vertical field of view (used by --width/--height).
    pub fn set_resolution(&mut self, width: u32, height: u32) {
        let aspect = width as f32 / height as f32;
        self.tan_half_x = self.tan_half_y * aspect;
        self.width = width;
        self.height = height;
        self.full_width = width;
        self.full_height = height;
        self.crop_offset = [0, 0];
    }

    pub fn position(&self) -> Vec3 {
        self.to_world.point(Vec3::ZERO)
    }

    /// Ray through film position (x, y) in pixels (continuous, origin top-left), with lens
    /// sample `u_lens`. The direction is unit length in world space.
    pub fn generate_ray(&self, film_x: f32, film_y: f32, u_lens: [f32; 2]) -> Ray {
        let nx = (film_x + self.crop_offset[0] as f32) / self.full_width as f32 * 2.0 - 1.0;
        let ny = (film_y + self.crop_offset[1] as f32) / self.full_height as f32 * 2.0 - 1.0;
        if self.projection == Projection::Orthographic {
            let aspect = self.full_width as f32 / self.full_height as f32;
            let o = self.to_world.point(vec3(-nx, -ny / aspect, self.near_clip));
            let dir = self.to_world.vector(Vec3::Z).normalize();
            // As Mitsuba: the ray runs far_clip - near_clip in world units from the near plane.
            return Ray { origin: o, dir, t_min: 0.0, t_max: self.far_clip - self.near_clip };
        }
        let d = vec3(-nx * self.tan_half_x, -ny * self.tan_half_y, 1.0);
        let (origin, dir) = if self.lens_radius > 0.0 {
            let focus = d * self.focus_distance;
            let l = warp::concentric_disk(u_lens);
            let o = vec3(l[0] * self.lens_radius, l[1] * self.lens_radius, 0.0);
            (o, focus - o)
        } else {
            (Vec3::ZERO, d)
        };
        let dir_cam = dir.normalize();
        let o = self.to_world.point(origin);
        let dw = self.to_world.vector(dir_cam);
        let len = dw.length();
        // Clip distances are along the camera's z axis; convert to distance along the ray.
        let z_per_t = dir_cam.z / len;
        Ray { origin: o, dir: dw / len, t_min: self.near_clip / z_per_t, t_max: self.far_clip / z_per_t }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_left_is_plus_x() {
        let t = Transform::look_at(vec3(0.0, 0.0, -5.0), Vec3::ZERO, Vec3::Y).unwrap();
        let cam = Camera::new(t, 100, 50, 40.0, FovAxis::Y);
        let r = cam.generate_ray(50.0, 25.0, [0.5, 0.5]);
        assert!((r.dir - Vec3::Z).length() < 1e-6);
        // Left edge of the image looks towards world +x for a camera looking along +z.
        assert!(cam.generate_ray(0.0, 25.0, [0.5, 0.5]).dir.x > 0.0);
        // Top of the image looks up.
        assert!(cam.generate_ray(50.0, 0.0, [0.5, 0.5]).dir.y > 0.0);
        // Vertical field of view is 40 degrees.
        let top = cam.generate_ray(50.0, 0.0, [0.5, 0.5]).dir;
        assert!((top.y.atan2(top.z).to_degrees() - 20.0).abs() < 1e-3);
    }

    #[test]
    fn orthographic_rays_are_parallel_and_span_mitsubas_window() {
        let t = Transform::look_at(vec3(0.0, 0.0, -5.0), Vec3::ZERO, Vec3::Y).unwrap();
        let scaled = t.then_after(&Transform::scale(vec3(2.0, 2.0, 1.0)).unwrap());
        let mut cam = Camera::new(scaled, 100, 50, 40.0, FovAxis::X);
        cam.projection = Projection::Orthographic;
        cam.near_clip = 0.5;
        cam.far_clip = 10.0;
        for (x, y) in [(0.0, 0.0), (50.0, 25.0), (100.0, 50.0), (13.0, 41.0)] {
            let r = cam.generate_ray(x, y, [0.5, 0.5]);
            assert!((r.dir - Vec3::Z).length() < 1e-6);
            assert!((r.origin.z - (-4.5)).abs() < 1e-5);
            assert_eq!((r.t_min, r.t_max), (0.0, 9.5));
        }
        // Left edge: camera x = +1 (world +x here), scaled by 2; top edge: y = 1/aspect = 0.5.
        assert!((cam.generate_ray(0.0, 25.0, [0.5; 2]).origin.x - 2.0).abs() < 1e-5);
        assert!((cam.generate_ray(50.0, 0.0, [0.5; 2]).origin.y - 1.0).abs() < 1e-5);
    }

    #[test]
    fn a_crop_window_traces_the_full_images_rays() {
        let t = Transform::look_at(vec3(1.0, 2.0, -5.0), Vec3::ZERO, Vec3::Y).unwrap();
        for projection in [Projection::Perspective, Projection::Orthographic] {
            let mut full = Camera::new(t, 64, 48, 50.0, FovAxis::X);
            full.projection = projection;
            let mut crop = full.clone();
            crop.set_crop(CropWindow { offset_x: 10, offset_y: 7, width: 20, height: 30 });
            assert_eq!((crop.width, crop.height), (20, 30));
            for (x, y) in [(0.0, 0.0), (19.5, 29.5), (3.25, 11.0)] {
                let (a, b) = (crop.generate_ray(x, y, [0.5; 2]), full.generate_ray(x + 10.0, y + 7.0, [0.5; 2]));
                assert!((a.origin - b.origin).length() < 1e-6 && (a.dir - b.dir).length() < 1e-6);
            }
        }
    }
}
