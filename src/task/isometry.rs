//! The plane isometries of a pattern symmetry and the group they form, with its action on
//! G0 (built and checked in `task::symmetry`).

/// Largest order of rotational symmetry accepted.
pub const MAX_ROTATIONS: usize = 12;

/// A plane isometry `x ↦ m x + c`: a rotation by `theta` (`reflects` false) or the
/// reflection about a line at angle `theta / 2` followed by a translation (`reflects`
/// true).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isometry {
    /// The linear part.
    pub m: [[f64; 2]; 2],
    /// The translation.
    pub c: [f64; 2],
    /// Whether it reverses orientation.
    pub reflects: bool,
    /// Rotation angle, or twice the mirror line's angle.
    pub theta: f64,
}

impl Isometry {
    /// The identity.
    pub fn identity() -> Isometry {
        Isometry::linear(false, 0.0, [0.0, 0.0])
    }

    fn linear(reflects: bool, theta: f64, c: [f64; 2]) -> Isometry {
        let (s, co) = theta.sin_cos();
        let m = if reflects {
            [[co, s], [s, -co]]
        } else {
            [[co, -s], [s, co]]
        };
        Isometry {
            m,
            c,
            reflects,
            theta,
        }
    }

    /// The rotation by `theta` about `center`.
    pub fn rotation(center: [f64; 2], theta: f64) -> Isometry {
        let r = Isometry::linear(false, theta, [0.0, 0.0]);
        let rc = r.apply(center);
        Isometry::linear(false, theta, [center[0] - rc[0], center[1] - rc[1]])
    }

    /// The reflection about the line through `p` and `q`.
    pub fn reflection(p: [f64; 2], q: [f64; 2]) -> Isometry {
        let phi = (q[1] - p[1]).atan2(q[0] - p[0]);
        let r = Isometry::linear(true, 2.0 * phi, [0.0, 0.0]);
        let rp = r.apply(p);
        Isometry::linear(true, 2.0 * phi, [p[0] - rp[0], p[1] - rp[1]])
    }

    /// The image of point `p`.
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.m[0][0] * p[0] + self.m[0][1] * p[1] + self.c[0],
            self.m[1][0] * p[0] + self.m[1][1] * p[1] + self.c[1],
        ]
    }

    /// The direction angle of the image of a direction at angle `a`.
    pub fn angle(&self, a: f64) -> f64 {
        if self.reflects {
            self.theta - a
        } else {
            a + self.theta
        }
    }

    /// `self ∘ other` (first `other`, then `self`).
    pub fn then_after(&self, other: &Isometry) -> Isometry {
        let c = self.apply(other.c);
        let reflects = self.reflects != other.reflects;
        let theta = match (self.reflects, other.reflects) {
            (false, false) | (false, true) => self.theta + other.theta,
            (true, false) => self.theta - other.theta,
            (true, true) => self.theta - other.theta,
        };
        let theta = theta.rem_euclid(std::f64::consts::TAU);
        Isometry::linear(reflects, theta, c)
    }

    pub(crate) fn close_to(&self, o: &Isometry, tol: f64) -> bool {
        self.reflects == o.reflects
            && (0..2).all(|i| (self.c[i] - o.c[i]).abs() <= tol)
            && (0..2).all(|i| (0..2).all(|j| (self.m[i][j] - o.m[i][j]).abs() <= 1e-9))
    }
}

/// The symmetry group of a pattern with its action on G0.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// The elements; `elements[0]` is the identity.
    pub elements: Vec<Isometry>,
    /// `mul[a][b]`: the index of `elements[a] ∘ elements[b]`.
    pub mul: Vec<Vec<usize>>,
    /// `vertex[g][v]`: the G0 vertex at the image of G0 vertex `v`.
    pub vertex: Vec<Vec<usize>>,
    /// `crease[g][c]`: the image of G0 crease `c` (directions kept).
    pub crease: Vec<Vec<usize>>,
    /// `facet[g][f]`: the image of G0 facet `f`.
    pub facet: Vec<Vec<usize>>,
    /// The order of the rotations (1: none).
    pub rotations: usize,
    /// The centre of rotation.
    pub center: [f64; 2],
    /// The mirror axis, as two points, if the pattern is its own mirror image.
    pub mirror_axis: Option<[[f64; 2]; 2]>,
}

impl Group {
    /// Number of elements.
    pub fn order(&self) -> usize {
        self.elements.len()
    }

    /// The inverse of element `g`.
    pub fn inverse(&self, g: usize) -> usize {
        (0..self.order())
            .find(|&h| self.mul[g][h] == 0)
            .expect("a group has inverses")
    }

    /// Whether element `g` reverses orientation.
    pub fn reflects(&self, g: usize) -> bool {
        self.elements[g].reflects
    }

    /// The G0 vertex standing for the orbit of G0 vertex `v`: the first of its images in
    /// file order, and the element taking that representative to `v`.
    pub fn g0_source(&self, v: usize) -> (usize, usize) {
        orbit_source(&self.vertex, v)
    }

    /// As [`Group::g0_source`] for a G0 crease.
    pub fn g0_crease_source(&self, c: usize) -> (usize, usize) {
        orbit_source(&self.crease, c)
    }
}

/// The least image of `x` under the permutations `perm` (one per element, the identity
/// among them) and the element taking it to `x`.
fn orbit_source(perm: &[Vec<usize>], x: usize) -> (usize, usize) {
    let rep = perm.iter().map(|p| p[x]).min().expect("the identity");
    let g = perm
        .iter()
        .position(|p| p[rep] == x)
        .expect("x is in rep's orbit");
    (rep, g)
}

/// The symmetry as the task file gives it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PatternSymmetry {
    /// Order of rotational symmetry (1: none).
    pub rotations: usize,
    /// The centre of rotation (default: the centroid of G0's vertices).
    pub center: Option<[f64; 2]>,
    /// Two points of the mirror axis.
    pub mirror_axis: Option<[[f64; 2]; 2]>,
}

impl PatternSymmetry {
    /// Whether the pattern has a symmetry.
    pub fn any(&self) -> bool {
        self.rotations > 1 || self.mirror_axis.is_some()
    }
}
