//! Evaluation of a [`Plan`], generic over [`Scalar`]: the same code builds the symbolic
//! model and computes the numeric reference.
//!
//! 3D coordinates follow SPEC §3's facet formulation: every facet has a rigid map
//! `X = R_f x + c_f`; crossing a crease counter-clockwise around a vertex, along the flat
//! ray `d` from the vertex, from the facet right of the ray to the facet left of it,
//! `R_left = R_right · Rot(d, ρ)` with the crease's dihedral angle ρ (valley positive),
//! and `c` keeps the vertex in place. The initial graph's two facets start at
//! `Rot(d, ±ρ/2)` about its driven crease.

use super::linalg::{self, Mat3, Vec3};
use super::plan::{Plan, Position, Sector};
use crate::kinematics::{Scalar, Unit, VertexState, solve_vertex};
use std::f64::consts::PI;

/// The t-independent part: the crease pattern in the plane.
#[derive(Clone, Debug)]
pub struct Flat<S> {
    /// In-plane position of every vertex.
    pub pos: Vec<[S; 2]>,
    /// Unit direction of every ray of every vertex (as in [`super::plan::Vertex::rays`]).
    pub dirs: Vec<Vec<[S; 2]>>,
    /// Every sector of every vertex (as in [`super::plan::Vertex::sectors`]).
    pub sectors: Vec<Vec<S>>,
}

/// The folded state at one t.
#[derive(Clone, Debug)]
pub struct Folded<S> {
    /// Dihedral angle of every crease (valley positive).
    pub rho: Vec<S>,
    /// The PTU solution at every internal vertex (`None` for the others).
    pub states: Vec<Option<VertexState<S>>>,
    /// Rotation of every facet's rigid map.
    pub rot: Vec<Mat3<S>>,
    /// Translation of every facet's rigid map.
    pub trans: Vec<Vec3<S>>,
}

/// Angle of the direction from `from` to `to` with an exact expression where the plan
/// has one (placement angles) and `atan2` of the coordinates otherwise.
fn direction_angle<S: Scalar>(
    plan: &Plan,
    pos: &[[S; 2]],
    ang: &[Option<S>],
    from: usize,
    to: usize,
) -> S {
    if let (Some((parent, crease)), Some(a)) = (plan.vertices[to].position.placed_from(), &ang[to])
        && parent == from
        && plan.creases[crease].head == to
    {
        return a.clone();
    }
    if let (Some((parent, crease)), Some(a)) =
        (plan.vertices[from].position.placed_from(), &ang[from])
        && parent == to
        && plan.creases[crease].head == from
    {
        return a.clone() + PI;
    }
    if let (Position::Fixed(p), Position::Fixed(q)) =
        (&plan.vertices[from].position, &plan.vertices[to].position)
    {
        return S::from_f64((q[1] - p[1]).atan2(q[0] - p[0]));
    }
    let dy = pos[to][1].clone() - pos[from][1].clone();
    let dx = pos[to][0].clone() - pos[from][0].clone();
    dy.atan2(&dx)
}

/// Every vertex's in-plane position and, where r1 placed it (or its image), the exact
/// angle of its placing crease (Eq. 28).
fn positions<S: Scalar>(plan: &Plan, vars: &[S]) -> (Vec<[S; 2]>, Vec<Option<S>>) {
    let n = plan.vertices.len();
    let zero = || [S::from_f64(0.0), S::from_f64(0.0)];
    let mut pos: Vec<[S; 2]> = (0..n).map(|_| zero()).collect();
    let mut ang: Vec<Option<S>> = vec![None; n];
    for &i in &plan.position_order {
        let v = &plan.vertices[i];
        match &v.position {
            Position::Fixed(xy) => {
                pos[i] = [S::from_f64(xy[0]), S::from_f64(xy[1])];
            }
            Position::Placed {
                parent,
                reference,
                sign,
                sectors,
                length,
                ..
            } => {
                let base = direction_angle(plan, &pos, &ang, *parent, *reference);
                let turn = sectors
                    .iter()
                    .fold(S::from_f64(0.0), |acc, s| acc + vars[*s].clone());
                let a = base + turn * *sign;
                let l = vars[*length].clone();
                pos[i] = [
                    pos[*parent][0].clone() + l.clone() * a.cos(),
                    pos[*parent][1].clone() + l * a.sin(),
                ];
                ang[i] = Some(a);
            }
            Position::Between { a, b } => {
                pos[i] = [
                    (pos[*a][0].clone() + pos[*b][0].clone()) * 0.5,
                    (pos[*a][1].clone() + pos[*b][1].clone()) * 0.5,
                ];
            }
            Position::Image {
                source,
                element,
                parent,
            } => {
                let g = &plan.isometries[*element];
                let [x, y] = pos[*source].clone();
                pos[i] = [
                    x.clone() * g.m[0][0] + y.clone() * g.m[0][1] + g.c[0],
                    x * g.m[1][0] + y * g.m[1][1] + g.c[1],
                ];
                ang[i] = match (parent, &ang[*source]) {
                    (Some(_), Some(a)) if g.reflects => Some(-a.clone() + g.theta),
                    (Some(_), Some(a)) => Some(a.clone() + g.theta),
                    _ => None,
                };
            }
        }
    }
    (pos, ang)
}

/// The pattern in the plane for the given variable values (sector angles in radians,
/// lengths) — Eq. 28 and the sectors of Eq. 29, 31, 34, 35.
pub fn flat<S: Scalar>(plan: &Plan, vars: &[S]) -> Flat<S> {
    let n = plan.vertices.len();
    let (pos, ang) = positions(plan, vars);
    let mut dirs = Vec::with_capacity(n);
    let mut sectors = Vec::with_capacity(n);
    for (i, v) in plan.vertices.iter().enumerate() {
        let d: Vec<[S; 2]> = v
            .rays
            .iter()
            .map(|r| {
                let exact = match (
                    plan.vertices[r.other].position.placed_from(),
                    plan.vertices[i].position.placed_from(),
                ) {
                    (Some((parent, crease)), _)
                        if r.outgoing && parent == i && crease == r.crease =>
                    {
                        ang[r.other].clone()
                    }
                    (_, Some((parent, crease)))
                        if !r.outgoing && parent == r.other && crease == r.crease =>
                    {
                        ang[i].clone().map(|a| a + PI)
                    }
                    _ => None,
                };
                match exact {
                    Some(a) => [a.cos(), a.sin()],
                    None => {
                        let dx = pos[r.other][0].clone() - pos[i][0].clone();
                        let dy = pos[r.other][1].clone() - pos[i][1].clone();
                        let len = (dx.clone() * dx.clone() + dy.clone() * dy.clone()).sqrt();
                        [dx / len.clone(), dy / len]
                    }
                }
            })
            .collect();
        let nr = d.len();
        let mut s: Vec<Option<S>> = v
            .sectors
            .iter()
            .enumerate()
            .map(|(k, rule)| match rule {
                Sector::Linear(terms) => Some(
                    terms
                        .iter()
                        .fold(S::from_f64(0.0), |acc, (c, x)| acc + vars[*x].clone() * *c),
                ),
                Sector::Constant(c) => Some(S::from_f64(*c)),
                Sector::Remainder | Sector::Image { .. } => None,
                Sector::Geometric => {
                    let (u, w) = (&d[k], &d[(k + 1) % nr]);
                    let cross = u[0].clone() * w[1].clone() - u[1].clone() * w[0].clone();
                    let dot = u[0].clone() * w[0].clone() + u[1].clone() * w[1].clone();
                    Some(cross.atan2(&dot))
                }
            })
            .collect();
        if let Some(r) = v.sectors.iter().position(|x| *x == Sector::Remainder) {
            let others = s
                .iter()
                .flatten()
                .fold(S::from_f64(0.0), |acc, x| acc + x.clone());
            s[r] = Some(S::from_f64(2.0 * PI) - others);
        }
        sectors.push(s);
        dirs.push(d);
    }
    // An image's sectors are its representative's (computed above: a representative is
    // never an image).
    let copies: Vec<Vec<Option<S>>> = plan
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| {
            v.sectors
                .iter()
                .enumerate()
                .map(|(k, rule)| match rule {
                    Sector::Image { vertex, k: j } => sectors[*vertex][*j].clone(),
                    _ => sectors[i][k].clone(),
                })
                .collect()
        })
        .collect();
    let sectors = copies
        .into_iter()
        .map(|s| {
            s.into_iter()
                .map(|x| x.expect("every sector computed"))
                .collect()
        })
        .collect();
    Flat { pos, dirs, sectors }
}

/// The units of internal vertex `a` (Eq. 29): u1 = (s3→p1, p1→p2, …, pm→s1) driven by
/// the incoming creases, u2 = (s1→s2), u3 = (s2→s3).
pub fn units<S: Scalar>(
    plan: &Plan,
    flat: &Flat<S>,
    rho: &[Option<S>],
    a: usize,
) -> Option<[Unit<S>; 3]> {
    let v = &plan.vertices[a];
    let (m, n) = (v.preds, v.rays.len());
    let s = &flat.sectors[a];
    let mut u1 = vec![s[n - 1].clone()];
    u1.extend(s[..m].iter().cloned());
    let mut drive = Vec::with_capacity(m);
    for r in &v.rays[..m] {
        drive.push(rho[r.crease].clone()?);
    }
    Some([
        Unit::new(u1, drive),
        Unit::single(s[m].clone()),
        Unit::single(s[m + 1].clone()),
    ])
}

/// The folded state at `t` with rigid body modes `modes` (±1 per mode parameter,
/// [`Plan::n_modes`]; every internal vertex folds by [`Plan::vertex_modes`]).
pub fn fold<S: Scalar>(plan: &Plan, flat: &Flat<S>, modes: &[S], t: &S) -> Folded<S> {
    let modes = plan.vertex_modes(modes);
    let mut rho: Vec<Option<S>> = plan
        .creases
        .iter()
        .map(|c| c.drive.as_ref().map(|d| d.eval(t)))
        .collect();
    let mut states: Vec<Option<VertexState<S>>> = vec![None; plan.vertices.len()];
    for (k, &a) in plan.internal.iter().enumerate() {
        let units = units(plan, flat, &rho, a)
            .expect("incoming dihedral angles are known in extension order");
        let st = solve_vertex(&units, &modes[k]);
        let v = &plan.vertices[a];
        let m = v.preds;
        // ρ(a→s1) = φ3, ρ(a→s2) = φ1, ρ(a→s3) = φ2 (Sec. 5.2.1.4).
        for (slot, phi) in [(0, 2), (1, 0), (2, 1)] {
            rho[v.rays[m + slot].crease] = Some(st.phi[phi].clone());
        }
        states[a] = Some(st);
    }
    let zero = || S::from_f64(0.0);
    let rho: Vec<S> = rho.into_iter().map(|r| r.unwrap_or_else(zero)).collect();

    // Facet maps.
    let nf = plan.facets;
    let mut rot: Vec<Mat3<S>> = vec![linalg::identity(); nf];
    let mut trans: Vec<Vec3<S>> = vec![[zero(), zero(), zero()]; nf];
    let about = |c: usize| {
        let cr = &plan.creases[c];
        let (tail, head) = (&flat.pos[cr.tail], &flat.pos[cr.head]);
        let (dx, dy) = (
            head[0].clone() - tail[0].clone(),
            head[1].clone() - tail[1].clone(),
        );
        let len = (dx.clone() * dx.clone() + dy.clone() * dy.clone()).sqrt();
        let x_tail: Vec3<S> = [tail[0].clone(), tail[1].clone(), zero()];
        (dx / len.clone(), dy / len, x_tail)
    };
    let turns: Vec<(usize, usize, S)> = match plan.actuation.fixed {
        // One facet stays (identity); crossing a driven crease from the facet right of it
        // to the left turns by +ρ (SPEC §3), the other way by −ρ.
        Some(fixed) => plan
            .actuation
            .driven
            .iter()
            .map(|&c| {
                let cr = &plan.creases[c];
                if cr.right == fixed {
                    (c, cr.left, rho[c].clone())
                } else {
                    (c, cr.right, -rho[c].clone())
                }
            })
            .collect(),
        None => {
            let c = plan.actuation.crease;
            let act = &plan.creases[c];
            let half = rho[c].clone() * 0.5;
            vec![(c, act.left, half.clone()), (c, act.right, -half)]
        }
    };
    for (c, f, angle) in turns {
        let (dx, dy, x_tail) = about(c);
        let r = linalg::rot_in_plane_axis(&dx, &dy, &angle);
        trans[f] = linalg::sub(&x_tail, &linalg::apply(&r, &x_tail));
        rot[f] = r;
    }
    for step in &plan.walk {
        let v = step.vertex;
        let d = &flat.dirs[v][step.ray];
        let crease = plan.vertices[v].rays[step.ray].crease;
        let turn = linalg::rot_in_plane_axis(&d[0], &d[1], &rho[crease]);
        let r = linalg::mul(&rot[step.from], &turn);
        let x: Vec3<S> = [flat.pos[v][0].clone(), flat.pos[v][1].clone(), zero()];
        let xv = linalg::add(&linalg::apply(&rot[step.from], &x), &trans[step.from]);
        trans[step.facet] = linalg::sub(&xv, &linalg::apply(&r, &x));
        rot[step.facet] = r;
    }
    Folded {
        rho,
        states,
        rot,
        trans,
    }
}

/// 3D position of vertex `v` (read through its home facet).
pub fn position<S: Scalar>(plan: &Plan, flat: &Flat<S>, folded: &Folded<S>, v: usize) -> Vec3<S> {
    position_on(flat, folded, v, plan.home_facet[v])
}

/// 3D position of vertex `v` read through facet `f`'s map.
pub fn position_on<S: Scalar>(flat: &Flat<S>, folded: &Folded<S>, v: usize, f: usize) -> Vec3<S> {
    let x: Vec3<S> = [
        flat.pos[v][0].clone(),
        flat.pos[v][1].clone(),
        S::from_f64(0.0),
    ];
    linalg::add(&linalg::apply(&folded.rot[f], &x), &folded.trans[f])
}

/// The global rotation of crease `c` (thesis Eq. 30 and below): the rotation taking the
/// crease's local frame — x along the crease from its tail, z the paper's normal — to the
/// folded state, so that `X_head = X_tail + l · R · e_x`. It is the map of the facet right
/// of the crease composed with the crease's in-plane direction.
pub fn crease_rotation<S: Scalar>(
    plan: &Plan,
    flat: &Flat<S>,
    folded: &Folded<S>,
    c: usize,
) -> Mat3<S> {
    let cr = &plan.creases[c];
    let (p, q) = (&flat.pos[cr.tail], &flat.pos[cr.head]);
    let (dx, dy) = (q[0].clone() - p[0].clone(), q[1].clone() - p[1].clone());
    let l = (dx.clone() * dx.clone() + dy.clone() * dy.clone()).sqrt();
    let (c0, s0) = (dx / l.clone(), dy / l);
    let z = S::from_f64(0.0);
    let local = [
        [c0.clone(), -s0.clone(), z.clone()],
        [s0, c0, z.clone()],
        [z.clone(), z, S::from_f64(1.0)],
    ];
    linalg::mul(&folded.rot[cr.right], &local)
}
