//! The independent check of thick panels (issue 32): the actual solids of a design built
//! by [`crate::fabricate`], moved by each facet's rigid motion to every state of the dense
//! sweep, tested pair by pair as triangle meshes. It shares no code with the optimizer's
//! inflated clearances ([`crate::model::robust`]) that it judges.
//!
//! At every state:
//! - two panels whose facets share no vertex (nor meet by design, see
//!   [`ThickInput::touching`]) keep at least `clearance` apart: the least
//!   triangle–triangle distance ([`super::distance::triangle_distance`]) of their closed
//!   meshes, 0 when one contains the other (winding number of a point just inside the
//!   other);
//! - two panels whose facets share a crease or a vertex, or meet by design, touch at most:
//!   no two of their triangles cross ([`super::tri_tri::triangles_intersect`] with
//!   [`TOUCH_TOL`]) and neither contains the other. Tapered panels of one crease meet at the
//!   crease's largest fold by construction;
//! - every panel keeps `obstacle_clearance` from every obstacle
//!   ([`super::shapes::facet_clearance`] on its triangles).
//!
//! Bounding spheres skip a pair only where they prove it clear.

use super::distance::triangle_distance;
use super::shapes::facet_clearance;
use super::tri_tri::{Tri, triangles_intersect};
use crate::fabricate::{Solid, ThickDesign};
use crate::pattern::Pattern;
use crate::scene::Obstacle;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

/// Contact tolerance of two panels that may touch (paper units): triangles crossing by
/// less than this count as contact.
pub const TOUCH_TOL: f64 = 1e-9;

/// What the check looks at.
pub struct ThickInput<'a> {
    /// The checked pattern (the arm with its copies), its frames the dense sweep.
    pub pattern: &'a Pattern,
    /// Its thick panels, built for the folds of those frames.
    pub design: &'a ThickDesign,
    /// Paper units: panels that share no vertex keep this apart.
    pub clearance: f64,
    /// Paper units: every panel keeps this from every obstacle.
    pub obstacle_clearance: f64,
    /// The task's obstacles.
    pub obstacles: &'a [Obstacle],
    /// Pairs of vertices that meet by design (the tips of a two-armed gripper at its
    /// target): facets holding one each may touch, like facets sharing a vertex.
    pub touching: &'a [(usize, usize)],
}

/// Where a thick panel fails.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThickHit {
    /// The state's t.
    pub t: f64,
    /// The panels (facet indices of the checked pattern); one for an obstacle.
    pub facets: Vec<usize>,
    /// What: `"clearance"` (apart panels closer than the clearance), `"crossing"` (panels
    /// that may touch cross), `"obstacle"`.
    pub kind: String,
    /// The distance measured (paper units; 0 for a crossing).
    pub distance: f64,
    /// The obstacle's name, for an obstacle hit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstacle: Option<String>,
}

/// What the check found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThickReport {
    /// States tested.
    pub states: usize,
    /// Pairs of panels tested at each state (apart and touching).
    pub pairs: usize,
    /// The least distance between two apart panels over the sweep (paper units; `None` when
    /// no pair is apart, so nothing was measured: JSON has no infinity).
    pub least_apart: Option<f64>,
    /// The least clearance of a panel from an obstacle (paper units; `None` without
    /// obstacles).
    pub least_obstacle: Option<f64>,
    /// The clearance required between apart panels.
    pub clearance: f64,
    /// The clearance required from obstacles.
    pub obstacle_clearance: f64,
    /// Pairs that may touch and were found crossing, over the sweep.
    pub crossings: usize,
    /// The first failure found, if any.
    pub first_failure: Option<ThickHit>,
}

impl ThickReport {
    /// Whether every panel kept its clearances and no touching pair crossed.
    pub fn passes(&self) -> bool {
        self.first_failure.is_none()
    }
}

/// How two panels are judged.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Rule {
    /// At least the clearance apart.
    Apart,
    /// Touching allowed, crossing not.
    Touch,
}

/// One solid as triangles with its bounding sphere and a point inside it.
struct Placed {
    tris: Vec<Tri>,
    centre: Vector3<f64>,
    radius: f64,
    /// A point strictly inside: just behind the middle of its largest triangle. Not the
    /// mean of its corners, which lies outside a non-convex panel (and there may lie inside
    /// its neighbour, which made two panels that never meet "contain" each other).
    inside: Vector3<f64>,
}

/// A point just inside a closed, outward-oriented mesh: the centroid of its largest
/// triangle moved against that triangle's normal by a millionth of the mesh's size (far
/// less than any panel's thickness).
fn inside_point(tris: &[Tri], radius: f64) -> Vector3<f64> {
    let normal = |t: &Tri| (t[1] - t[0]).cross(&(t[2] - t[0]));
    let Some(big) = tris
        .iter()
        .max_by(|a, b| normal(a).norm().total_cmp(&normal(b).norm()))
    else {
        return Vector3::zeros();
    };
    let n = normal(big);
    let centroid = (big[0] + big[1] + big[2]) / 3.0;
    centroid - n * (1e-6 * radius / n.norm().max(f64::MIN_POSITIVE))
}

fn place(s: &Solid) -> Placed {
    let pts: Vec<Vector3<f64>> = s.vertices.iter().map(|p| Vector3::from(*p)).collect();
    let centre = pts.iter().sum::<Vector3<f64>>() / pts.len().max(1) as f64;
    let radius = pts.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    let tris: Vec<Tri> = s
        .triangles
        .iter()
        .map(|t| [pts[t[0]], pts[t[1]], pts[t[2]]])
        .collect();
    let inside = inside_point(&tris, radius);
    Placed {
        tris,
        centre,
        radius,
        inside,
    }
}

/// Generalized winding number of a closed, outward-oriented triangle set about `p`.
fn winding(tris: &[Tri], p: &Vector3<f64>) -> f64 {
    let total: f64 = tris
        .iter()
        .map(|t| {
            let [a, b, c] = [t[0] - p, t[1] - p, t[2] - p];
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let num = a.dot(&b.cross(&c));
            let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
            2.0 * num.atan2(den)
        })
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

/// Whether one of two solids holds a point inside the other: with surfaces that do not
/// cross, one contains the other exactly then.
fn contains(a: &Placed, b: &Placed) -> bool {
    winding(&a.tris, &b.inside).abs() > 0.5 || winding(&b.tris, &a.inside).abs() > 0.5
}

/// The least distance between two closed meshes, stopping early below `stop`; 0 when one
/// contains the other.
fn mesh_distance(a: &Placed, b: &Placed, stop: f64) -> f64 {
    let mut least = f64::INFINITY;
    for ta in &a.tris {
        for tb in &b.tris {
            least = least.min(triangle_distance(ta, tb));
            if least < stop {
                return least;
            }
        }
    }
    if contains(a, b) { 0.0 } else { least }
}

/// Whether every corner of `b` lies within [`TOUCH_TOL`] of `a`'s plane.
fn coplanar(a: &Tri, b: &Tri) -> bool {
    let n = (a[1] - a[0]).cross(&(a[2] - a[0]));
    let len = n.norm();
    len > 0.0
        && b.iter()
            .all(|p| (n.dot(&(p - a[0])) / len).abs() <= TOUCH_TOL)
}

/// Whether two meshes that may touch cross (or one contains the other). Coplanar
/// triangles are faces in contact (two panels flat against each other, or the faces of
/// two slabs meeting at a hinge): where closed solids overlap, other triangles cross.
fn crosses(a: &Placed, b: &Placed) -> bool {
    a.tris.iter().any(|ta| {
        b.tris
            .iter()
            .any(|tb| !coplanar(ta, tb) && triangles_intersect(ta, tb, TOUCH_TOL))
    }) || contains(a, b)
}

/// The rule of every pair of facets `(i, j)`, `i < j`.
fn rules(pattern: &Pattern, touching: &[(usize, usize)]) -> Vec<(usize, usize, Rule)> {
    let sets: Vec<HashSet<usize>> = pattern
        .faces
        .iter()
        .map(|f| f.iter().copied().collect())
        .collect();
    let meets = |i: usize, j: usize| {
        touching.iter().any(|&(u, v)| {
            (sets[i].contains(&u) && sets[j].contains(&v))
                || (sets[i].contains(&v) && sets[j].contains(&u))
        })
    };
    let mut out = Vec::new();
    for i in 0..sets.len() {
        for j in i + 1..sets.len() {
            let rule = if sets[i].is_disjoint(&sets[j]) && !meets(i, j) {
                Rule::Apart
            } else {
                Rule::Touch
            };
            out.push((i, j, rule));
        }
    }
    out
}

/// Test the thick panels of `input.design` at every frame of `input.pattern`.
pub fn check(input: &ThickInput<'_>) -> ThickReport {
    let pairs = rules(input.pattern, input.touching);
    let mut r = ThickReport {
        states: input.pattern.frames.len(),
        pairs: pairs.len(),
        least_apart: None,
        least_obstacle: None,
        clearance: input.clearance,
        obstacle_clearance: input.obstacle_clearance,
        crossings: 0,
        first_failure: None,
    };
    for frame in &input.pattern.frames {
        let solids: Vec<Placed> = input
            .design
            .solids_at(input.pattern, frame)
            .iter()
            .map(place)
            .collect();
        let fail = |r: &mut ThickReport, hit: ThickHit| {
            r.first_failure.get_or_insert(hit);
        };
        for &(i, j, rule) in &pairs {
            let (a, b) = (&solids[i], &solids[j]);
            let apart = (a.centre - b.centre).norm() - a.radius - b.radius;
            match rule {
                Rule::Apart => {
                    // Spheres farther apart than the least so far cannot lower it.
                    if r.least_apart.is_some_and(|least| apart >= least) {
                        continue;
                    }
                    let d = mesh_distance(a, b, -1.0);
                    r.least_apart = Some(r.least_apart.map_or(d, |least| least.min(d)));
                    if d < input.clearance {
                        fail(&mut r, hit(frame.t, vec![i, j], "clearance", d, None));
                    }
                }
                Rule::Touch => {
                    // Disjoint spheres: the solids cannot cross.
                    if apart <= TOUCH_TOL && crosses(a, b) {
                        r.crossings += 1;
                        fail(&mut r, hit(frame.t, vec![i, j], "crossing", 0.0, None));
                    }
                }
            }
        }
        for o in input.obstacles {
            for (f, s) in solids.iter().enumerate() {
                let Some(c) = facet_clearance(&o.shape, &s.tris) else {
                    continue;
                };
                r.least_obstacle = Some(r.least_obstacle.map_or(c, |least| least.min(c)));
                if c < input.obstacle_clearance {
                    fail(
                        &mut r,
                        hit(frame.t, vec![f], "obstacle", c, Some(o.name.clone())),
                    );
                }
            }
        }
    }
    r
}

fn hit(
    t: f64,
    facets: Vec<usize>,
    kind: &str,
    distance: f64,
    obstacle: Option<String>,
) -> ThickHit {
    ThickHit {
        t,
        facets,
        kind: kind.to_string(),
        distance,
        obstacle,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fabricate::{Layer, Panel};
    use crate::pattern::{Edge, EdgeKind, Frame};
    use crate::task::fabrication::{FabMethod, Fabrication, Sides};

    const T: f64 = 0.02;

    fn spec() -> Fabrication {
        Fabrication {
            thickness: 2.0,
            scale: 100.0,
            method: FabMethod::Tapered,
            sides: Sides::One,
            hinge_gap: 0.0,
            min_width: 0.0,
        }
    }

    /// Untrimmed slabs `[0, T]` over every facet (what the check sees is all that matters).
    fn slabs(p: &Pattern) -> ThickDesign {
        let panels = p
            .faces
            .iter()
            .enumerate()
            .map(|(f, face)| Panel {
                facet: f,
                layers: [0.0, T]
                    .map(|offset| Layer {
                        offset,
                        outline: face.iter().map(|&v| p.vertices[v]).collect(),
                    })
                    .to_vec(),
            })
            .collect();
        ThickDesign {
            spec: spec(),
            panels,
            hinges: Vec::new(),
        }
    }

    fn run(p: &Pattern, clearance: f64) -> ThickReport {
        check(&ThickInput {
            pattern: p,
            design: &slabs(p),
            clearance,
            obstacle_clearance: 0.0,
            obstacles: &[],
            touching: &[],
        })
    }

    /// Two unit squares far apart in the flat layout; in the one frame the second lies over
    /// the first at height `h`, upright (`flip` false) or turned over about a line parallel
    /// to x (its slab then points down, toward the first).
    fn stacked(h: f64, flip: bool) -> Pattern {
        let sq = |x: f64| [[x, 0.0], [x + 1.0, 0.0], [x + 1.0, 1.0], [x, 1.0]];
        let vertices: Vec<[f64; 2]> = sq(0.0).into_iter().chain(sq(3.0)).collect();
        let mut coords: Vec<[f64; 3]> = sq(0.0).iter().map(|p| [p[0], p[1], 0.0]).collect();
        coords.extend(sq(0.0).iter().map(|p| {
            if flip {
                [p[0], 1.0 - p[1], h]
            } else {
                [p[0], p[1], h]
            }
        }));
        Pattern {
            vertices,
            edges: Vec::new(),
            faces: vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]],
            frames: vec![Frame {
                t: 1.0,
                coords,
                fold_angles: Vec::new(),
            }],
        }
    }

    #[test]
    fn stacked_slabs_are_their_facets_distance_less_the_reach_of_each() {
        // Upright: the slabs span [0, T] and [h, h + T]: h − T apart.
        let r = run(&stacked(0.1, false), 0.05);
        let least = r.least_apart.unwrap();
        assert!((least - (0.1 - T)).abs() < 1e-12, "{least}");
        assert!(r.passes());
        // Turned over: [0, T] and [h − T, h]: h − 2T apart — the reduction's bound is tight.
        let r = run(&stacked(0.1, true), 0.05);
        let least = r.least_apart.unwrap();
        assert!((least - (0.1 - 2.0 * T)).abs() < 1e-12, "{least}");
        assert!(r.passes());
        let r = run(&stacked(0.1, true), 0.07);
        let hit = r.first_failure.unwrap();
        assert_eq!(
            (hit.kind.as_str(), hit.facets.clone()),
            ("clearance", vec![0, 1])
        );
        // Overlapping slabs are 0 apart, even when one surface lies inside the other.
        let r = run(&stacked(0.5 * T, false), 0.0);
        assert_eq!(r.least_apart, Some(0.0));
    }

    #[test]
    fn a_non_convex_panel_does_not_contain_what_lies_in_its_notch() {
        // An L-shaped facet (arms 0.2 wide) and a square in its notch, 0.2 from both arms,
        // flat: the mean of the L's corners, (0.733, 0.733), lies inside the square, yet
        // the slabs are 0.2 apart and neither contains the other.
        let l = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 0.2],
            [0.2, 0.2],
            [0.2, 2.0],
            [0.0, 2.0],
        ];
        let sq = [[0.4, 0.4], [1.2, 0.4], [1.2, 1.2], [0.4, 1.2]];
        let vertices: Vec<[f64; 2]> = l.iter().chain(&sq).copied().collect();
        let coords = vertices.iter().map(|v| [v[0], v[1], 0.0]).collect();
        let p = Pattern {
            vertices,
            edges: Vec::new(),
            faces: vec![(0..6).collect(), (6..10).collect()],
            frames: vec![Frame {
                t: 0.0,
                coords,
                fold_angles: Vec::new(),
            }],
        };
        let r = run(&p, 0.1);
        let least = r.least_apart.unwrap();
        assert!((least - 0.2).abs() < 1e-12, "{least}");
        assert!(r.passes(), "{:?}", r.first_failure);
        // The same two sharing a vertex (the square grown to the L's inner corner) touch
        // there and do not cross.
        let mut p = p;
        p.vertices[6] = [0.2, 0.2];
        p.frames[0].coords[6] = [0.2, 0.2, 0.0];
        p.faces[1] = vec![3, 7, 8, 9];
        let r = run(&p, 0.1);
        assert_eq!(
            (r.crossings, r.passes()),
            (0, true),
            "{:?}",
            r.first_failure
        );
    }

    #[test]
    fn a_report_without_obstacles_reads_back_as_written() {
        // JSON has no infinity: a distance never measured (no obstacle here) must not be
        // written as a number the record reader then refuses (the robotic arm's records).
        let r = run(&stacked(0.1, false), 0.05);
        assert_eq!(r.least_obstacle, None);
        let text = serde_json::to_string(&r).unwrap();
        let back: ThickReport = serde_json::from_str(&text).unwrap();
        assert_eq!(back, r);
    }

    /// Two unit squares hinged along x = 1, the second folded by `rho` (valley > 0: toward
    /// +z, the side of the slabs).
    fn hinged(rho: f64) -> Pattern {
        let vertices = vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [2.0, 0.0],
            [2.0, 1.0],
        ];
        let out = [1.0 + rho.cos(), 0.0, rho.sin()];
        let coords = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            out,
            [out[0], 1.0, out[2]],
        ];
        Pattern {
            vertices,
            edges: vec![Edge {
                v: [1, 2],
                kind: EdgeKind::Crease { driven: false },
            }],
            faces: vec![vec![0, 1, 2, 3], vec![1, 4, 5, 2]],
            frames: vec![Frame {
                t: 1.0,
                coords,
                fold_angles: Vec::new(),
            }],
        }
    }

    #[test]
    fn untrimmed_slabs_cross_at_a_valley_and_not_at_a_mountain() {
        // Valley: the slabs meet on their own side of the hinge and, untrimmed, overlap
        // there (what the tapered trimming removes).
        let r = run(&hinged(0.3), 0.01);
        assert_eq!(r.first_failure.unwrap().kind, "crossing");
        // Mountain: they open away from each other; touching along the hinge line only.
        let r = run(&hinged(-0.3), 0.01);
        assert!(r.passes(), "{:?}", r.first_failure);
        assert_eq!(r.crossings, 0);
        // Flat: coplanar slabs sharing a face along the hinge touch, they do not cross.
        assert!(run(&hinged(0.0), 0.01).passes());
    }
}
