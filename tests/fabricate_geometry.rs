//! Thick panels (issue 32) judged by geometry written here, not by the construction's own
//! formulas: triangle–triangle distances between the folded solids, watertightness and
//! volume by the divergence theorem, rigid motions fitted independently (Kabsch).
//!
//! Random degree-4 and degree-5 vertices are folded by the PTU (`kinematics`); every
//! crease's two panels must be apart before the crease's largest fold and touch at it.

use foldsynth::fabricate::{self, FabError, FoldRange, Solid, ThickDesign};
use foldsynth::geom::{self, V3};
use foldsynth::kinematics::{
    DriveExpr, Mode, UnitSpec, VertexSpec, ccw_sequence, closure_residual, foldability,
    solve_vertex,
};
use foldsynth::pattern::{Edge, EdgeKind, Frame, Pattern};
use foldsynth::task::fabrication::{FabMethod, Fabrication, Sides};
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

// ---------- exact distances (Ericson, Real-Time Collision Detection, 5.1) ----------

fn closest_on_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
    let (ab, ac, ap) = (geom::sub(b, a), geom::sub(c, a), geom::sub(p, a));
    let (d1, d2) = (geom::dot(ab, ap), geom::dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = geom::sub(p, b);
    let (d3, d4) = (geom::dot(ab, bp), geom::dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return geom::add(a, geom::scale(ab, d1 / (d1 - d3)));
    }
    let cp = geom::sub(p, c);
    let (d5, d6) = (geom::dot(ab, cp), geom::dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return geom::add(a, geom::scale(ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return geom::add(b, geom::scale(geom::sub(c, b), w));
    }
    let den = 1.0 / (va + vb + vc);
    let (v, w) = (vb * den, vc * den);
    geom::add(a, geom::add(geom::scale(ab, v), geom::scale(ac, w)))
}

fn segment_segment(p1: V3, q1: V3, p2: V3, q2: V3) -> f64 {
    let (d1, d2, r) = (geom::sub(q1, p1), geom::sub(q2, p2), geom::sub(p1, p2));
    let (a, e, f) = (geom::dot(d1, d1), geom::dot(d2, d2), geom::dot(d2, r));
    let (s, t);
    if a <= 1e-300 && e <= 1e-300 {
        return geom::dist(p1, p2);
    }
    if a <= 1e-300 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = geom::dot(d1, r);
        if e <= 1e-300 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = geom::dot(d1, d2);
            let den = a * e - b * b;
            let s0 = if den > 0.0 {
                ((b * f - c * e) / den).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    geom::dist(
        geom::add(p1, geom::scale(d1, s)),
        geom::add(p2, geom::scale(d2, t)),
    )
}

/// Whether the segment `p q` meets the triangle (Möller–Trumbore, closed).
fn segment_hits_triangle(p: V3, q: V3, t: [V3; 3]) -> bool {
    let d = geom::sub(q, p);
    let (e1, e2) = (geom::sub(t[1], t[0]), geom::sub(t[2], t[0]));
    let h = geom::cross(d, e2);
    let a = geom::dot(e1, h);
    if a.abs() < 1e-300 {
        return false;
    }
    let f = 1.0 / a;
    let s = geom::sub(p, t[0]);
    let u = f * geom::dot(s, h);
    let qv = geom::cross(s, e1);
    let v = f * geom::dot(d, qv);
    let w = f * geom::dot(e2, qv);
    (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && (0.0..=1.0).contains(&w)
}

fn triangle_triangle(a: [V3; 3], b: [V3; 3]) -> f64 {
    for k in 0..3 {
        if segment_hits_triangle(a[k], a[(k + 1) % 3], b)
            || segment_hits_triangle(b[k], b[(k + 1) % 3], a)
        {
            return 0.0;
        }
    }
    let mut m = f64::INFINITY;
    for k in 0..3 {
        m = m.min(geom::dist(
            a[k],
            closest_on_triangle(a[k], b[0], b[1], b[2]),
        ));
        m = m.min(geom::dist(
            b[k],
            closest_on_triangle(b[k], a[0], a[1], a[2]),
        ));
        for j in 0..3 {
            m = m.min(segment_segment(a[k], a[(k + 1) % 3], b[j], b[(j + 1) % 3]));
        }
    }
    m
}

fn tri(s: &Solid, t: [usize; 3]) -> [V3; 3] {
    t.map(|i| s.vertices[i])
}

/// The distance from the triangles `which` of `a` to all of `b`.
fn part_to_solid(a: &Solid, which: &[usize], b: &Solid) -> f64 {
    let mut m = f64::INFINITY;
    for &i in which {
        for &tb in &b.triangles {
            m = m.min(triangle_triangle(tri(a, a.triangles[i]), tri(b, tb)));
        }
    }
    m
}

/// Triangles of a flat solid whose three corners are at height `z` (a cap).
fn cap(flat: &Solid, z: f64) -> Vec<usize> {
    (0..flat.triangles.len())
        .filter(|&i| {
            flat.triangles[i]
                .iter()
                .all(|&v| (flat.vertices[v][2] - z).abs() < 1e-12)
        })
        .collect()
}

// ---------- closed meshes ----------

fn assert_closed_outward(s: &Solid) {
    let mut directed = std::collections::HashMap::new();
    for t in &s.triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "facet {}: edge {a}→{b} used {n} times", s.facet);
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "facet {}: edge {a}→{b} has no opposite",
            s.facet
        );
    }
    assert!(volume(s) > 0.0, "facet {}: volume {}", s.facet, volume(s));
}

/// Divergence theorem: Σ a·(b × c)/6.
fn volume(s: &Solid) -> f64 {
    s.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = tri(s, *t);
            geom::dot(a, geom::cross(b, c)) / 6.0
        })
        .sum()
}

// ---------- random vertices folded by the PTU ----------

/// A random vertex of degree `n`, sectors summing to 360°, each 25°–150°.
fn random_spec(rng: &mut ChaCha8Rng, n: usize) -> VertexSpec {
    let sizes = if n == 4 { [2, 1, 1] } else { [2, 2, 1] };
    let sectors = loop {
        let w: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..1.5)).collect();
        let sum: f64 = w.iter().sum();
        let s: Vec<f64> = w.iter().map(|x| x / sum * 360.0).collect();
        if s.iter().all(|a| (25.0..150.0).contains(a)) {
            break s;
        }
    };
    let mut k = 0;
    let units = sizes.map(|m| {
        let u = UnitSpec {
            sectors_deg: sectors[k..k + m].to_vec(),
            driving: (0..m - 1)
                .map(|_| DriveExpr::parse(if rng.random_bool(0.5) { "t" } else { "-t" }).unwrap())
                .collect(),
        };
        k += m;
        u
    });
    let mode = if rng.random_bool(0.5) {
        Mode::Up
    } else {
        Mode::Down
    };
    VertexSpec { mode, units }
}

/// The vertex as a pattern (centre 0, outer corners 1..=n at random radii), folded at
/// `ts`: facet k lies in the xy-plane of `M_k = Π_{j<k} R_z(α_j) R_x(ρ_j)`.
fn vertex_pattern(rng: &mut ChaCha8Rng, spec: &VertexSpec, ts: &[f64]) -> Option<Pattern> {
    let n = spec.degree();
    let radii: Vec<f64> = (0..n).map(|_| rng.random_range(0.8..1.3)).collect();
    let mut vertices = vec![[0.0, 0.0]];
    let mut theta = 0.0f64;
    for (k, a) in spec.sectors_rad().iter().enumerate() {
        vertices.push([radii[k] * theta.cos(), radii[k] * theta.sin()]);
        theta += a;
    }
    let mut edges = Vec::new();
    for k in 1..=n {
        edges.push(Edge {
            v: [0, k],
            kind: EdgeKind::Crease { driven: false },
        });
        edges.push(Edge {
            v: [k, k % n + 1],
            kind: EdgeKind::Boundary,
        });
    }
    let faces = (1..=n).map(|k| vec![0, k, k % n + 1]).collect();
    let mut frames = Vec::new();
    for &t in ts {
        let units = spec.units_at(t);
        let st = solve_vertex(&units, &spec.mode.sign());
        if closure_residual(&units, &st.phi) > 1e-10 {
            return None;
        }
        let seq = ccw_sequence(&units, &st.phi);
        let mut m = Matrix3::identity();
        let mut coords = vec![[0.0; 3]];
        for (k, &(a, rho)) in seq.iter().enumerate() {
            let d = m * Vector3::x();
            coords.push([d[0] * radii[k], d[1] * radii[k], d[2] * radii[k]]);
            m = m
                * Rotation3::from_axis_angle(&Vector3::z_axis(), a).matrix()
                * Rotation3::from_axis_angle(&Vector3::x_axis(), rho).matrix();
        }
        frames.push(Frame {
            t,
            coords,
            fold_angles: vec![0.0; edges.len()],
        });
    }
    Some(Pattern {
        vertices,
        edges,
        faces,
        frames,
    })
}

fn spec(sides: Sides, thickness: f64, gap: f64) -> Fabrication {
    Fabrication {
        thickness,
        scale: 100.0,
        method: FabMethod::Tapered,
        sides,
        hinge_gap: gap,
        min_width: 0.0,
    }
}

/// Random rigid-foldable vertices of degree 4 and 5 with their swept motion: from t = 0
/// while the vertex stays rigid (Eq. 25) and closes, up to a random end below π.
fn random_vertices(seed: u64, count: usize) -> Vec<Pattern> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    for _ in 0..2000 {
        if out.len() == count {
            return out;
        }
        let n = if out.len() % 2 == 0 { 4 } else { 5 };
        let v = random_spec(&mut rng, n);
        let end = rng.random_range(1.0..2.6);
        let ts: Vec<f64> = (0..=48)
            .map(|i| end * i as f64 / 48.0)
            .take_while(|&t| foldability::min_margin(&v, t) >= -foldability::RIGID_TOL)
            .collect();
        if ts.len() < 12 {
            continue;
        }
        let Some(p) = vertex_pattern(&mut rng, &v, &ts) else {
            continue;
        };
        let r = fabricate::fold_ranges(&p, &p.frames);
        if r.iter().any(|r| r.largest() > 0.9 * PI) || r.iter().all(|r| r.largest() < 0.2) {
            continue;
        }
        out.push(p);
    }
    panic!("only {} random vertices fold rigidly", out.len());
}

/// The frames' fold angles by geometry agree with the construction's sweep, so the test's
/// motion is the one the PTU describes.
fn fold_of(p: &Pattern, frame: &Frame, edge: usize) -> f64 {
    let e = &p.edges[edge];
    let side = |a: usize, b: usize| {
        p.faces
            .iter()
            .position(|f| (0..f.len()).any(|k| f[k] == a && f[(k + 1) % f.len()] == b))
            .unwrap()
    };
    let pts = |f: usize| -> Vec<V3> { p.faces[f].iter().map(|&v| frame.coords[v]).collect() };
    let [a, b] = e.v;
    geom::fold_angle(
        frame.coords[a],
        frame.coords[b],
        &pts(side(a, b)),
        &pts(side(b, a)),
    )
    .unwrap()
}

/// Panels of one crease: the distance between the closing side's caps and the other
/// solid, at every frame: positive below the largest fold, zero at it.
fn check_touching(p: &Pattern, design: &ThickDesign, label: &str) {
    let flat = design.flat_solids();
    let [lo, hi] = design.spec.slab_units();
    let mut touched = 0;
    for h in &design.hinges {
        let [l, r] = h.facets;
        for (want, caps_z) in [(h.folds.valley, hi), (h.folds.mountain, lo)] {
            if caps_z == 0.0 || want < 0.2 {
                continue;
            }
            let (cl, cr) = (cap(&flat[l], caps_z), cap(&flat[r], caps_z));
            for frame in &p.frames {
                let rho = fold_of(p, frame, h.edge);
                let toward = if caps_z > 0.0 { rho } else { -rho };
                let solids = design.solids_at(p, frame);
                let d = part_to_solid(&solids[l], &cl, &solids[r])
                    .min(part_to_solid(&solids[r], &cr, &solids[l]));
                if (toward - want).abs() < 1e-12 {
                    assert!(d < 1e-9, "{label} crease {}: at ρ_max distance {d}", h.edge);
                    touched += 1;
                } else if toward < want - 0.02 {
                    assert!(
                        d > 1e-7,
                        "{label} crease {}: at ρ = {toward} < ρ_max = {want} distance {d}",
                        h.edge
                    );
                }
            }
        }
    }
    assert!(touched > 0, "{label}: no crease reached its largest fold");
}

#[test]
fn panels_touch_exactly_at_the_largest_fold_on_random_vertices() {
    for (i, p) in random_vertices(11, 8).iter().enumerate() {
        let ranges = fabricate::fold_ranges(p, &p.frames);
        for sides in [Sides::One, Sides::Both] {
            let design = fabricate::build(p, &ranges, &spec(sides, 3.0, 0.0)).unwrap();
            check_touching(
                p,
                &design,
                &format!("vertex {i} ({}, {sides:?})", p.faces.len()),
            );
        }
    }
}

#[test]
fn the_ptu_frames_fold_as_the_sequence_says() {
    // The test's folding is the PTU's: fold angles measured on the frames are the
    // sequence's ρ (valley positive), crease by crease.
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let v = random_spec(&mut rng, 5);
    let p = vertex_pattern(&mut rng, &v, &[0.7]).unwrap();
    let units = v.units_at(0.7);
    let st = solve_vertex(&units, &v.mode.sign());
    let seq = ccw_sequence(&units, &st.phi);
    for (k, &(_, rho)) in seq.iter().enumerate() {
        let crease = 2 * ((k + 1) % v.degree());
        let got = fold_of(&p, &p.frames[0], crease);
        let w = foldsynth::kinematics::wrap_angle(rho);
        assert!((got - w).abs() < 1e-9, "crease {crease}: {got} vs {w}");
    }
}

/// Kabsch: the rotation and translation taking `from` onto `to` (least squares).
fn kabsch(from: &[V3], to: &[V3]) -> (Matrix3<f64>, Vector3<f64>) {
    let c = |ps: &[V3]| {
        ps.iter()
            .fold(Vector3::zeros(), |a, p| a + Vector3::from(*p))
            / ps.len() as f64
    };
    let (cf, ct) = (c(from), c(to));
    let mut h = Matrix3::zeros();
    for (a, b) in from.iter().zip(to) {
        h += (Vector3::from(*a) - cf) * (Vector3::from(*b) - ct).transpose();
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut d = Matrix3::identity();
    d[(2, 2)] = (vt.transpose() * u.transpose()).determinant().signum();
    let r = vt.transpose() * d * u.transpose();
    (r, ct - r * cf)
}

#[test]
fn solids_are_closed_and_move_rigidly_with_their_facets() {
    for p in random_vertices(5, 4) {
        let ranges = fabricate::fold_ranges(&p, &p.frames);
        for sides in [Sides::One, Sides::Both] {
            let design = fabricate::build(&p, &ranges, &spec(sides, 4.0, 0.5)).unwrap();
            let flat = design.flat_solids();
            for (s, panel) in flat.iter().zip(&design.panels) {
                assert_closed_outward(s);
                // Simpson's rule is exact for a loft whose corners move linearly.
                let mut want = 0.0;
                for w in panel.layers.windows(2) {
                    let mid: Vec<[f64; 2]> = w[0]
                        .outline
                        .iter()
                        .zip(&w[1].outline)
                        .map(|(a, b)| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0])
                        .collect();
                    want += (w[1].offset - w[0].offset) / 6.0
                        * (geom::signed_area_2d(&w[0].outline)
                            + 4.0 * geom::signed_area_2d(&mid)
                            + geom::signed_area_2d(&w[1].outline));
                }
                assert!((volume(s) - want).abs() < 1e-12 * want.max(1e-9) + 1e-15);
            }
            for frame in p.frames.iter().step_by(7) {
                let moved = design.solids_at(&p, frame);
                for (f, face) in p.faces.iter().enumerate() {
                    let from: Vec<V3> = face
                        .iter()
                        .map(|&v| [p.vertices[v][0], p.vertices[v][1], 0.0])
                        .collect();
                    let to: Vec<V3> = face.iter().map(|&v| frame.coords[v]).collect();
                    let (r, t) = kabsch(&from, &to);
                    for (a, b) in flat[f].vertices.iter().zip(&moved[f].vertices) {
                        let want = r * Vector3::from(*a) + t;
                        assert!((want - Vector3::from(*b)).amax() < 1e-9);
                    }
                    assert_closed_outward(&moved[f]);
                }
                // Hinge axes: both panels carry the crease line where the frame has it.
                for h in &design.hinges {
                    for (k, &v) in h.vertices.iter().enumerate() {
                        for f in h.facets {
                            let m = fabricate::facet_motion(&p, f, frame);
                            let x = m.apply([h.axis[k][0], h.axis[k][1], 0.0]);
                            assert!(geom::dist(x, frame.coords[v]) < 1e-9);
                        }
                    }
                }
            }
        }
    }
}

/// Two square facets on one crease, folded analytically (no kinematics) to any angle.
fn two_facets(angles: &[f64]) -> Pattern {
    let vertices = vec![
        [0.0, -1.0],
        [1.0, -1.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [-1.0, -1.0],
        [-1.0, 1.0],
    ];
    let b = |a, c| Edge {
        v: [a, c],
        kind: EdgeKind::Boundary,
    };
    let edges = vec![
        Edge {
            v: [0, 3],
            kind: EdgeKind::Crease { driven: true },
        },
        b(0, 1),
        b(1, 2),
        b(2, 3),
        b(3, 5),
        b(5, 4),
        b(4, 0),
    ];
    // Left of 0 → 3 (+y) is the facet with x < 0: turning it about +y by +ρ raises it
    // toward +z, a valley (geom's sign).
    let faces = vec![vec![0, 1, 2, 3], vec![3, 5, 4, 0]];
    let frames = angles
        .iter()
        .map(|&rho| {
            let rot = Rotation3::from_axis_angle(&Vector3::y_axis(), rho);
            let coords = vertices
                .iter()
                .map(|p: &[f64; 2]| {
                    if p[0] < 0.0 {
                        let q = rot * Vector3::new(p[0], p[1], 0.0);
                        [q[0], q[1], q[2]]
                    } else {
                        [p[0], p[1], 0.0]
                    }
                })
                .collect();
            Frame {
                t: rho,
                coords,
                fold_angles: vec![0.0; 7],
            }
        })
        .collect();
    Pattern {
        vertices,
        edges,
        faces,
        frames,
    }
}

/// Whether `x` lies strictly inside a convex closed solid (behind every face plane).
fn strictly_inside(s: &Solid, x: V3) -> bool {
    s.triangles.iter().all(|t| {
        let [a, b, c] = tri(s, *t);
        let n = geom::cross(geom::sub(b, a), geom::sub(c, a));
        geom::norm(n) < 1e-14 || geom::dot(n, geom::sub(x, a)) < -1e-12
    })
}

#[test]
fn a_crease_that_changes_sign_is_trimmed_on_both_sides() {
    let (v, m) = (1.9, 1.2);
    let p = two_facets(&[v, 0.5, 0.0, -0.4, -m]);
    let ranges = fabricate::fold_ranges(&p, &p.frames);
    assert!((ranges[0].valley - v).abs() < 1e-12 && (ranges[0].mountain - m).abs() < 1e-12);
    let design = fabricate::build(&p, &ranges, &spec(Sides::Both, 20.0, 0.0)).unwrap();
    check_touching(&p, &design, "sign change");
    // A little past either largest fold, the panels overlap: a corner of one panel's
    // closing cap lies inside the other panel.
    let [lo, hi] = design.spec.slab_units();
    let flat = design.flat_solids();
    for (rho, z) in [(v + 0.05, hi), (-(m + 0.05), lo)] {
        let past = two_facets(&[rho]);
        let solids = design.solids_at(&past, &past.frames[0]);
        let corners: Vec<usize> = (0..flat[1].vertices.len())
            .filter(|&i| (flat[1].vertices[i][2] - z).abs() < 1e-12)
            .collect();
        // Midpoints of the cap's sides: the one along the crease goes in first.
        let inside = corners.iter().any(|&i| {
            corners.iter().any(|&j| {
                let mid = geom::scale(geom::add(solids[1].vertices[i], solids[1].vertices[j]), 0.5);
                strictly_inside(&solids[0], mid)
            })
        });
        assert!(inside, "no overlap past ρ = {rho}");
    }
    // With one side only, a mountain fold opens the slab: no trimming at the bottom.
    let one = fabricate::build(&p, &ranges, &spec(Sides::One, 20.0, 0.0)).unwrap();
    assert_eq!(one.hinges[0].setback[1], 0.0);
    assert!(one.hinges[0].setback[0] > 0.0);
    let past = two_facets(&[-(PI - 0.05)]);
    let solids = one.solids_at(&past, &past.frames[0]);
    let top = cap(&one.flat_solids()[1], one.spec.slab_units()[1]);
    assert!(part_to_solid(&solids[1], &top, &solids[0]) > 1e-6);
}

#[test]
fn what_cannot_be_built_is_refused_naming_the_crease() {
    let p = two_facets(&[1.0]);
    let mut ranges = fabricate::fold_ranges(&p, &p.frames);
    // Folded flat.
    ranges[0].valley = PI;
    match fabricate::build(&p, &ranges, &spec(Sides::One, 1.0, 0.0)) {
        Err(FabError::FoldsFlat {
            edge: 0,
            a: 0,
            b: 3,
            ..
        }) => {}
        other => panic!("{other:?}"),
    }
    ranges[0] = FoldRange {
        valley: 2.5,
        mountain: 0.0,
    };
    // tan(1.25)·t > 1 unit: the panel vanishes (scale 100 mm/unit, 50 mm thick).
    let e = fabricate::build(&p, &ranges, &spec(Sides::One, 50.0, 0.0)).unwrap_err();
    assert!(matches!(e, FabError::Vanishes { edge: 0, .. }), "{e:?}");
    assert!(e.to_string().contains("crease 0"), "{e}");
    // Thin but present: refused by min_width.
    let mut s = spec(Sides::One, 10.0, 0.0);
    s.min_width = 80.0;
    let e = fabricate::build(&p, &ranges, &s).unwrap_err();
    assert!(matches!(e, FabError::TooThin { edge: 0, .. }), "{e:?}");
    for (field, bad) in [("thickness", 0.0), ("thickness", f64::NAN), ("scale", 0.0)] {
        let mut s = spec(Sides::One, 1.0, 0.0);
        if field == "scale" {
            s.scale = bad;
        } else {
            s.thickness = bad;
        }
        match fabricate::build(&p, &ranges, &s) {
            Err(FabError::Setting { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{other:?}"),
        }
    }
}
