//! Orthographic cameras framed on a scene's bounds: the same box gives the same camera, so
//! an input and its output drawn with one camera line up pixel for pixel.

use glam::Vec3;
use rayon::prelude::*;

/// Points to frame, as a parallel iterator (scenes can hold millions of vertices).
pub type Points<'a> = rayon::iter::Flatten<rayon::vec::IntoIter<&'a [Vec3]>>;

/// Where the camera looks from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum View {
    /// From +Z (glTF's front), +Y up.
    Front,
    /// From +X, +Y up.
    Side,
    /// From +Y, −Z up.
    Top,
    /// From (1, 1, 1), +Y up: all three axes at once.
    Iso,
}

impl View {
    /// Every view, in the order pictures show them.
    pub const ALL: [View; 4] = [View::Front, View::Side, View::Top, View::Iso];

    /// The unit direction towards the camera and the screen's up direction.
    fn axes(self) -> (Vec3, Vec3) {
        match self {
            View::Front => (Vec3::Z, Vec3::Y),
            View::Side => (Vec3::X, Vec3::Y),
            View::Top => (Vec3::Y, Vec3::NEG_Z),
            View::Iso => (Vec3::ONE.normalize(), Vec3::Y),
        }
    }
}

/// Empty space around the framed box, as a fraction of the picture's side.
const MARGIN: f32 = 0.05;

/// An orthographic camera onto a square picture of `size` pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Screen right, in world space.
    pub right: Vec3,
    /// Screen up, in world space.
    pub up: Vec3,
    /// Towards the viewer, in world space.
    pub toward: Vec3,
    /// The world point at the picture's centre.
    pub center: Vec3,
    /// Pixels per world unit.
    pub scale: f32,
    /// Side of the picture in pixels.
    pub size: u32,
}

impl Camera {
    /// Frames `points` (a unit box when there are none) from `view`: their projection is
    /// centred and fills the picture but for a margin. The same points give the same camera.
    pub fn framing<'a>(points: impl Fn() -> Points<'a>, view: View, size: u32) -> Camera {
        let (toward, up0) = view.axes();
        let right = up0.cross(toward).normalize();
        let up = toward.cross(right);
        let screen = |p: &Vec3| Vec3::new(p.dot(right), p.dot(up), p.dot(toward));
        let extent = points()
            .filter(|p| p.is_finite())
            .map(|p| {
                let s = screen(p);
                (s, s)
            })
            .reduce(
                || (Vec3::INFINITY, Vec3::NEG_INFINITY),
                |a, b| (a.0.min(b.0), a.1.max(b.1)),
            );
        let (lo, hi) = match extent.0.x <= extent.1.x {
            true => extent,
            false => (Vec3::splat(-1.0), Vec3::ONE),
        };
        let mid = (lo + hi) * 0.5;
        let center = right * mid.x + up * mid.y + toward * mid.z;
        let half = ((hi.x - lo.x).max(hi.y - lo.y) * 0.5).max(1e-30);
        let scale = size as f32 * (0.5 - MARGIN) / half;
        Camera {
            right,
            up,
            toward,
            center,
            scale: if scale.is_finite() { scale } else { 1.0 },
            size,
        }
    }

    /// Screen position (pixels, y down, pixel centres at half-integers) and depth (smaller is
    /// nearer) of world point `p`.
    #[inline]
    pub fn project(&self, p: Vec3) -> [f32; 3] {
        let d = p - self.center;
        let half = self.size as f32 * 0.5;
        [
            half + d.dot(self.right) * self.scale,
            half - d.dot(self.up) * self.scale,
            -d.dot(self.toward),
        ]
    }

    /// `n` (world space) in the camera's frame: x right, y up, z towards the viewer.
    #[inline]
    pub fn to_view(&self, n: Vec3) -> Vec3 {
        Vec3::new(n.dot(self.right), n.dot(self.up), n.dot(self.toward))
    }
}
