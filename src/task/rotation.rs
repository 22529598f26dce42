//! The counter-clockwise order of the creases around each vertex of G0, from the
//! coordinates and the facet labels: its predecessors p1 … pm, its slots s1 s2 s3 and the
//! open sector where new creases go.

use super::{Ctx, InitialCrease, InitialVertex, TaskError, VertexType};

/// Angles closer than this are one direction (two creases on top of each other).
const ANGLE_EPS: f64 = 1e-9;

/// The facet on the counter-clockwise / clockwise side of crease `c` seen from vertex `v`.
fn sides(c: &InitialCrease, v: usize) -> (usize, usize) {
    if c.tail == v {
        (c.left, c.right)
    } else {
        (c.right, c.left)
    }
}

/// Incident creases sorted counter-clockwise by direction.
pub(crate) fn ring_at(
    cx: &Ctx<'_>,
    vs: &[InitialVertex],
    cs: &[InitialCrease],
    v: usize,
) -> Result<Vec<usize>, TaskError> {
    let p = vs[v].xy;
    let mut rays: Vec<(f64, usize)> = cs
        .iter()
        .enumerate()
        .filter(|(_, c)| c.tail == v || c.head == v)
        .map(|(i, c)| {
            let o = vs[if c.tail == v { c.head } else { c.tail }].xy;
            ((o[1] - p[1]).atan2(o[0] - p[0]), i)
        })
        .collect();
    rays.sort_by(|a, b| a.0.total_cmp(&b.0));
    for k in 1..rays.len() {
        if rays[k].0 - rays[k - 1].0 < ANGLE_EPS {
            let (a, b) = (&cs[rays[k - 1].1], &cs[rays[k].1]);
            return Err(cx.err(
                "initial_graph.creases",
                format!(
                    "creases {}→{} and {}→{} leave vertex \"{}\" in the same direction",
                    vs[a.tail].id, vs[a.head].id, vs[b.tail].id, vs[b.head].id, vs[v].id
                ),
            ));
        }
    }
    Ok(rays.into_iter().map(|r| r.1).collect())
}

/// Derive preds (p1 … pm), slots and the ring of vertex `v` from its ccw ring.
pub(crate) fn order_vertex(
    cx: &Ctx<'_>,
    vs: &mut [InitialVertex],
    cs: &[InitialCrease],
    facets: &[String],
    v: usize,
    ring: Vec<usize>,
) -> Result<(), TaskError> {
    let n = ring.len();
    // Sector k lies counter-clockwise from ring[k] to ring[k+1]; it is closed when one facet
    // fills it, i.e. both creases name the same facet on that side.
    let open: Vec<usize> = (0..n)
        .filter(|&k| sides(&cs[ring[k]], v).0 != sides(&cs[ring[(k + 1) % n]], v).1)
        .collect();
    let id = vs[v].id.clone();
    let field = format!("initial_graph.vertices[{v}]");
    let is_in = |c: usize| cs[c].head == v;
    let start = open.first().map_or(0, |&k| (k + 1) % n);
    let rotated: Vec<usize> = (0..n).map(|k| ring[(start + k) % n]).collect();

    if vs[v].ty == VertexType::Terminal {
        // Never extended or combined: any consistent arrangement is fine.
        let preds: Vec<usize> = rotated.iter().copied().filter(|&c| is_in(c)).collect();
        let outs: Vec<usize> = rotated.iter().copied().filter(|&c| !is_in(c)).collect();
        let mut slots = [None; 3];
        for (k, c) in outs.into_iter().enumerate() {
            slots[k] = Some(c);
        }
        let vx = &mut vs[v];
        // The true ccw order, for facet walks; preds and slots are storage only here.
        vx.ring = rotated;
        vx.preds = preds;
        vx.slots = slots;
        return Ok(());
    }

    if !rotated.iter().any(|&c| is_in(c)) {
        return Err(cx.err(
            format!("{field}.type"),
            format!("vertex \"{id}\" has no incoming crease (a source) and cannot be extendable: make it \"terminal\""),
        ));
    }
    let names = |k: usize| {
        let (a, b) = (sides(&cs[ring[k]], v).0, sides(&cs[ring[(k + 1) % n]], v).1);
        format!("{} | {}", facets[a], facets[b])
    };
    match open.len() {
        1 => {}
        0 => {
            return Err(cx.err(
                format!("{field}.type"),
                format!("every sector around extendable vertex \"{id}\" is closed by one facet, so new creases have nowhere to go; make it \"terminal\" or fix the facet labels"),
            ));
        }
        k => {
            return Err(cx.err(
                "initial_graph.creases",
                format!(
                    "inconsistent facet labels around extendable vertex \"{id}\": {k} sectors are open ({}); it needs exactly one open sector, where its new creases go",
                    open.iter().map(|&s| names(s)).collect::<Vec<_>>().join("; ")
                ),
            ));
        }
    }
    // After the open sector, going ccw: [outgoing before p1 (… s3)] p1 … pm [s1 (s2) after pm].
    let first_in = rotated.iter().position(|&c| is_in(c)).unwrap_or(0);
    let last_in = rotated.iter().rposition(|&c| is_in(c)).unwrap_or(0);
    if rotated[first_in..=last_in].iter().any(|&c| !is_in(c)) {
        return Err(cx.err(
            "initial_graph.creases",
            format!("at extendable vertex \"{id}\" an outgoing crease lies between incoming ones; its incoming creases must be adjacent (rotation p1 … pm s1 s2 s3)"),
        ));
    }
    let after_gap = &rotated[..first_in];
    let preds = rotated[first_in..=last_in].to_vec();
    let before_gap = &rotated[last_in + 1..];
    let mut slots = [None; 3];
    for (k, &c) in before_gap.iter().enumerate() {
        slots[k] = Some(c);
    }
    for (k, &c) in after_gap.iter().rev().enumerate() {
        slots[2 - k] = Some(c);
    }
    let vx = &mut vs[v];
    vx.ring = preds
        .iter()
        .chain(slots.iter().flatten())
        .copied()
        .collect();
    vx.preds = preds;
    vx.slots = slots;
    Ok(())
}
