//! Obstacles as the robustness block keeps facets clear of them (issue 31): every convex
//! obstacle is a set of support points plus an inflation radius, kept on the far side of a
//! separating plane from a facet (the plane at `radius + obstacle_clearance` from every
//! point); a half-space needs no plane (every vertex keeps its height above it).
//!
//! - cylinder: its axis ends, radius r (the capsule around the axis contains it);
//! - sphere: its centre, radius r;
//! - box: its 8 corners, 0;
//! - mesh: each triangle its 3 corners, 0 (a piece of its own, so that a facet is kept off
//!   the triangles near it; whether a closed mesh's inside holds a whole facet is left to
//!   the independent judge).

use crate::geom::{V3, add, dot, norm, scale, sub};
use crate::model::surface::closest_on_triangle;
use crate::scene::{HalfSpace, OrientedBox, Scene, Shape};

/// The hull of a convex piece's points, for the exact distance from a point to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hull {
    /// A segment (a cylinder's axis).
    Segment,
    /// A point (a sphere's centre).
    Point,
    /// A box.
    Box(OrientedBox),
    /// A triangle (of a mesh).
    Triangle,
}

/// One convex piece of an obstacle.
#[derive(Clone, Debug, PartialEq)]
pub struct Convex {
    /// The support points (the plane keeps every one `radius` + clearance away).
    pub points: Vec<V3>,
    /// Inflation radius (paper units).
    pub radius: f64,
    /// The points' hull.
    pub hull: Hull,
    /// Index of its obstacle in the scene.
    pub obstacle: usize,
    /// A ball containing the points (centre, radius; without the inflation).
    pub ball: (V3, f64),
}

impl Convex {
    fn new(points: Vec<V3>, radius: f64, hull: Hull, obstacle: usize) -> Convex {
        let c = scale(
            points.iter().fold([0.0; 3], |s, p| add(s, *p)),
            1.0 / points.len() as f64,
        );
        let r = points.iter().map(|p| norm(sub(*p, c))).fold(0.0, f64::max);
        Convex {
            points,
            radius,
            hull,
            obstacle,
            ball: (c, r),
        }
    }

    /// The exact distance from `c` to the hull of the points (the inflation not
    /// subtracted).
    pub fn distance(&self, c: V3) -> f64 {
        match self.hull {
            Hull::Segment => {
                let (a, b) = (self.points[0], self.points[1]);
                let ab = sub(b, a);
                let l = dot(ab, ab);
                let u = if l > 0.0 {
                    (dot(sub(c, a), ab) / l).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                norm(sub(c, add(a, scale(ab, u))))
            }
            Hull::Point => norm(sub(c, self.points[0])),
            Hull::Box(b) => {
                let q = b.local(c);
                let mut s = 0.0;
                for (qi, hi) in q.iter().zip(b.half) {
                    let e = qi.abs() - hi;
                    if e > 0.0 {
                        s += e * e;
                    }
                }
                s.sqrt()
            }
            Hull::Triangle => {
                let [a, b, t] = [self.points[0], self.points[1], self.points[2]];
                norm(sub(c, closest_on_triangle(c, &[a, b, t])))
            }
        }
    }

    /// Whether the rotation `turn` maps the points onto themselves (as a set, each within
    /// `tol`; 0: exactly): the copy's pairs with it are then the arm's pairs turned.
    pub fn symmetric(&self, turn: impl Fn(V3) -> V3, tol: f64) -> bool {
        self.points.iter().all(|p| {
            let q = turn(*p);
            self.points
                .iter()
                .any(|r| *r == q || norm(sub(*r, q)) <= tol)
        })
    }
}

/// The obstacles of a scene as the block sees them: the convex pieces (in the scene's
/// order, a mesh's triangles in its order) and the half-spaces (with their obstacle
/// index). A mesh not loaded has no pieces (the task loads every mesh it names).
pub fn pieces(scene: &Scene) -> (Vec<Convex>, Vec<(usize, HalfSpace)>) {
    let mut convex = Vec::new();
    let mut half = Vec::new();
    for (k, o) in scene.obstacles.iter().enumerate() {
        match &o.shape {
            Shape::Cylinder(c) => {
                convex.push(Convex::new(vec![c.a, c.b], c.radius, Hull::Segment, k))
            }
            Shape::Sphere(s) => convex.push(Convex::new(vec![s.center], s.radius, Hull::Point, k)),
            Shape::Box(b) => convex.push(Convex::new(b.corners().to_vec(), 0.0, Hull::Box(*b), k)),
            Shape::HalfSpace(h) => half.push((k, *h)),
            Shape::Mesh(m) => {
                if let Some(mesh) = m.triangles() {
                    for i in 0..mesh.triangles.len() {
                        let t = mesh.triangle(i);
                        convex.push(Convex::new(t.to_vec(), 0.0, Hull::Triangle, k));
                    }
                }
            }
        }
    }
    (convex, half)
}
