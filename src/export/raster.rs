//! Hard-edged drawing straight into GIF palette entries (issue 14).
//!
//! The GIF's frames were drawn anti-aliased with tiny-skia into RGBA and then mapped pixel
//! by pixel to the palette. Here a frame is a buffer of palette entries ([`Indexed`]), and
//! the primitive is a polygon filled by the nonzero rule at pixel centres (a pixel is
//! painted when its centre is inside). Wide strokes are thin polygons along their segments;
//! opaque strokes at most a pixel wide are hairlines, one pixel per column (per row when
//! steep). Opaque colours write their entry; translucent ones (the obstacle) go through a
//! 256-entry table "entry under it → entry of the blend", computed once per colour.
//! [`Canvas`] is what `render` draws a scene on: this picture or tiny-skia's pixmap.

use std::collections::HashMap;

use super::palette::GifPalette;

/// A colour to paint with: straight RGB and an alpha.
pub type Rgba = [u8; 4];

/// A picture as palette entries, row by row.
pub struct Indexed<'p> {
    w: usize,
    h: usize,
    /// The palette entry of each pixel.
    pub px: Vec<u8>,
    palette: &'p GifPalette,
    /// Per translucent colour: the entry of the blend over each entry.
    blends: HashMap<Rgba, [u8; 256]>,
    /// Crossings of the row being filled: `(x, winding direction)`, reused.
    crossings: Vec<(f64, i32)>,
    /// The edges of the polygon being filled, reused.
    edges: Vec<Edge>,
    /// The spans of the polygon being filled, reused.
    spans: Vec<[u32; 3]>,
    /// The spans of the translucent polygons drawn so far, by their coordinates' bits.
    kept: HashMap<Vec<u64>, Vec<[u32; 3]>>,
}

/// A polygon edge that is not horizontal.
struct Edge {
    x: f64,
    y: f64,
    slope: f64,
    lo: f64,
    hi: f64,
    dir: i32,
}

/// How a line is drawn: its colour, its width in pixels, and its dash lengths on and off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pen {
    /// The colour.
    pub color: Rgba,
    /// Width in pixels; an opaque pen at most 1 wide draws hairlines.
    pub width: f64,
    /// Lengths on and off, continued across corners; `None`: solid.
    pub dash: Option<[f64; 2]>,
}

/// What a picture is drawn on, in pixel coordinates (y down): [`Indexed`] for the GIF's
/// frames, tiny-skia's pixmap (anti-aliased) for the PNG pictures (`render`).
pub trait Canvas {
    /// Width and height in pixels.
    fn size(&self) -> (u32, u32);
    /// Fill the polygon `pts` (closed implicitly) by the nonzero winding rule.
    fn fill(&mut self, pts: &[[f64; 2]], color: Rgba);
    /// Stroke the polyline `pts` (closed when `close`) with butt ends.
    fn stroke(&mut self, pts: &[[f64; 2]], close: bool, pen: Pen);
    /// A disc of radius `r` around `c` in `fill` with a ring one pixel wide in `ring` on
    /// its edge (as a stroke of width 1 on the circle would be).
    fn dot(&mut self, c: [f64; 2], r: f64, fill: Rgba, ring: Rgba);
}

impl<'p> Indexed<'p> {
    /// A `w`×`h` picture filled with the entry of `background`.
    pub fn new(w: u32, h: u32, background: Rgba, palette: &'p GifPalette) -> Indexed<'p> {
        let (w, h) = (w as usize, h as usize);
        Indexed {
            w,
            h,
            px: vec![palette.index(background[0], background[1], background[2]); w * h],
            palette,
            blends: HashMap::new(),
            crossings: Vec::new(),
            edges: Vec::new(),
            spans: Vec::new(),
            kept: HashMap::new(),
        }
    }

    /// Fill the whole picture with the entry of `background` (the blend tables and the
    /// translucent polygons' spans stay).
    pub fn clear(&mut self, background: Rgba) {
        let e = self
            .palette
            .index(background[0], background[1], background[2]);
        if self.px.len() == self.w * self.h {
            self.px.fill(e);
        } else {
            // Taken by [`Indexed::take`]: a new buffer, filled as it is allocated.
            self.px = vec![e; self.w * self.h];
        }
    }

    /// The picture's entries, leaving it without pixels until the next [`Indexed::clear`]
    /// (drawing on it before then draws nothing), so a caller keeping every frame does not
    /// copy each one.
    pub fn take(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.px)
    }

    /// The spans `[row, first, end)` of the pixels whose centres are inside polygon `pts`
    /// by the nonzero winding rule, into `out` (cleared first).
    fn spans_of(&mut self, pts: &[[f64; 2]], out: &mut Vec<[u32; 3]>) {
        out.clear();
        if pts.len() < 3 || pts.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
            return;
        }
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[1]), hi.max(p[1]))
            });
        // Rows whose centre y + ½ lies in [lo, hi).
        let (first, last) = (centre_index(lo, self.h), centre_index(hi, self.h));
        // Each edge once: where it starts, its slope dx/dy, its rows' y range, its direction.
        let mut edges = std::mem::take(&mut self.edges);
        edges.clear();
        for (a, b) in pts.iter().zip(pts.iter().cycle().skip(1)) {
            if a[1] != b[1] {
                let (lo, hi) = if a[1] < b[1] {
                    (a[1], b[1])
                } else {
                    (b[1], a[1])
                };
                edges.push(Edge {
                    x: a[0],
                    y: a[1],
                    slope: (b[0] - a[0]) / (b[1] - a[1]),
                    lo,
                    hi,
                    dir: if b[1] > a[1] { 1 } else { -1 },
                });
            }
        }
        let mut crossings = std::mem::take(&mut self.crossings);
        for y in first..last {
            let yc = y as f64 + 0.5;
            crossings.clear();
            // Half-open in y, so a vertex on the row is counted once.
            crossings.extend(
                edges
                    .iter()
                    .filter(|e| e.lo <= yc && yc < e.hi)
                    .map(|e| (e.x + (yc - e.y) * e.slope, e.dir)),
            );
            crossings.sort_unstable_by(|p, q| p.0.total_cmp(&q.0));
            let mut winding = 0;
            for pair in crossings.windows(2) {
                winding += pair[0].1;
                if winding == 0 {
                    continue;
                }
                // Pixels whose centre x + ½ lies in [x0, x1).
                let (x0, x1) = (
                    centre_index(pair[0].0, self.w),
                    centre_index(pair[1].0, self.w),
                );
                if x0 < x1 {
                    out.push([y as u32, x0 as u32, x1 as u32]);
                }
            }
        }
        self.crossings = crossings;
        self.edges = edges;
    }

    /// The table of a translucent colour (built on first use).
    fn blend_table(&mut self, color: Rgba) -> [u8; 256] {
        let pal = self.palette;
        *self.blends.entry(color).or_insert_with(|| {
            let a = f64::from(color[3]) / 255.0;
            let mut t = [0u8; 256];
            for (i, e) in t.iter_mut().enumerate() {
                let under = pal.color(i as u8);
                let c = [0, 1, 2].map(|k| {
                    (f64::from(color[k]) * a + f64::from(under[k]) * (1.0 - a)).round() as u8
                });
                *e = pal.index(c[0], c[1], c[2]);
            }
            t
        })
    }

    /// One straight piece of a stroke: the rectangle `width` wide around `a`–`b`, or for
    /// an opaque stroke at most a pixel wide, a hairline.
    fn segment(&mut self, a: [f64; 2], b: [f64; 2], width: f64, color: Rgba) {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        // Not finite: nothing a hairline or a rectangle could be drawn from.
        if !(len.is_finite() && len > 0.0) {
            return;
        }
        if width <= 1.0 && color[3] == 255 {
            let e = self.palette.index(color[0], color[1], color[2]);
            self.hairline(a, b, e);
            return;
        }
        let (nx, ny) = (-dy / len * width / 2.0, dx / len * width / 2.0);
        self.fill(
            &[
                [a[0] + nx, a[1] + ny],
                [b[0] + nx, b[1] + ny],
                [b[0] - nx, b[1] - ny],
                [a[0] - nx, a[1] - ny],
            ],
            color,
        );
    }

    /// One pixel per column (per row, for a steep line) whose centre lies between the ends:
    /// the pixel the line crosses that centre line in.
    fn hairline(&mut self, a: [f64; 2], b: [f64; 2], entry: u8) {
        if self.px.len() != self.w * self.h {
            return;
        }
        // Along the major axis `m`, across it `c`; (w, h) in the same roles.
        let steep = (b[1] - a[1]).abs() > (b[0] - a[0]).abs();
        let (m, c, along, across) = if steep {
            (1, 0, self.h, self.w)
        } else {
            (0, 1, self.w, self.h)
        };
        let (p, q) = if a[m] <= b[m] { (a, b) } else { (b, a) };
        let slope = (q[c] - p[c]) / (q[m] - p[m]);
        for k in centre_index(p[m], along)..centre_index(q[m], along) {
            let at = p[c] + (k as f64 + 0.5 - p[m]) * slope;
            // The pixel containing `at` (floor, through i64: no libm call).
            let t = at as i64;
            let j = if (t as f64) > at { t - 1 } else { t };
            if (0..across as i64).contains(&j) {
                let j = j as usize;
                let i = if steep {
                    k * self.w + j
                } else {
                    j * self.w + k
                };
                self.px[i] = entry;
            }
        }
    }
}

impl Canvas for Indexed<'_> {
    fn size(&self) -> (u32, u32) {
        (self.w as u32, self.h as u32)
    }

    fn fill(&mut self, pts: &[[f64; 2]], color: Rgba) {
        if self.px.len() != self.w * self.h {
            return;
        }
        match color[3] {
            0 => {}
            255 => {
                let mut spans = std::mem::take(&mut self.spans);
                self.spans_of(pts, &mut spans);
                let e = self.palette.index(color[0], color[1], color[2]);
                for &[y, x0, x1] in &spans {
                    let row = y as usize * self.w;
                    self.px[row + x0 as usize..row + x1 as usize].fill(e);
                }
                self.spans = spans;
            }
            _ => {
                // Translucent polygons are the obstacle, the same in every frame: their
                // spans are kept, keyed by the exact coordinates.
                let key: Vec<u64> = pts.iter().flat_map(|p| p.map(f64::to_bits)).collect();
                let spans = match self.kept.remove(&key) {
                    Some(spans) => spans,
                    None => {
                        let mut spans = Vec::new();
                        self.spans_of(pts, &mut spans);
                        spans
                    }
                };
                let t = self.blend_table(color);
                for &[y, x0, x1] in &spans {
                    let row = y as usize * self.w;
                    for p in &mut self.px[row + x0 as usize..row + x1 as usize] {
                        *p = t[usize::from(*p)];
                    }
                }
                self.kept.insert(key, spans);
            }
        }
    }

    fn stroke(&mut self, pts: &[[f64; 2]], close: bool, pen: Pen) {
        let Pen { color, width, dash } = pen;
        let n = pts.len();
        let segments = if close && n > 2 {
            n
        } else {
            n.saturating_sub(1)
        };
        // Position in the dash pattern (arc length modulo its period).
        let mut phase = 0.0;
        for i in 0..segments {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            if len.is_nan() || len <= 0.0 {
                continue;
            }
            match dash.filter(|[on, off]| *on > 0.0 && *off >= 0.0) {
                // No dash, or none that can be walked: a solid line.
                None => self.segment(a, b, width, color),
                Some([on, off]) => {
                    let period = on + off;
                    let mut s = 0.0;
                    while s < len {
                        let p = (phase + s) % period;
                        let (drawn, step) = if p < on {
                            (true, on - p)
                        } else {
                            (false, period - p)
                        };
                        let e = (s + step).min(len);
                        if drawn {
                            let at = |t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
                            self.segment(at(s / len), at(e / len), width, color);
                        }
                        s = e;
                    }
                    phase = (phase + len) % period;
                }
            }
        }
    }

    fn dot(&mut self, c: [f64; 2], r: f64, fill: Rgba, ring: Rgba) {
        let circle = |r: f64| -> Vec<[f64; 2]> {
            (0..32)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / 32.0;
                    [c[0] + r * a.cos(), c[1] + r * a.sin()]
                })
                .collect()
        };
        self.fill(&circle(r + 0.5), ring);
        self.fill(&circle(r - 0.5), fill);
    }
}

/// The first pixel whose centre k + ½ is at or past `v`, clamped to 0..=`n`: ⌈v − ½⌉
/// without a call to libm's `ceil` (baseline x86-64 has no rounding instruction).
#[inline]
fn centre_index(v: f64, n: usize) -> usize {
    // NaN and negatives go to 0; values past n to n.
    // Through i64: one instruction each way, where usize's conversions take branches.
    let x = (v - 0.5).max(0.0).min(n as f64);
    let t = x as i64;
    (if (t as f64) < x { t + 1 } else { t }) as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::palette::gif_palette;

    const WHITE: Rgba = [255, 255, 255, 255];
    const INK: Rgba = [50, 50, 50, 255];

    /// A one-pixel pen in `INK`.
    fn pen(dash: Option<[f64; 2]>) -> Pen {
        Pen {
            color: INK,
            width: 1.0,
            dash,
        }
    }

    /// Whether `p` is inside polygon `pts` by the nonzero rule (winding number ≠ 0).
    fn inside(pts: &[[f64; 2]], p: [f64; 2]) -> bool {
        let mut w = 0;
        for (i, a) in pts.iter().enumerate() {
            let b = pts[(i + 1) % pts.len()];
            let cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
            if a[1] <= p[1] && b[1] > p[1] && cross > 0.0 {
                w += 1;
            } else if a[1] > p[1] && b[1] <= p[1] && cross < 0.0 {
                w -= 1;
            }
        }
        w != 0
    }

    #[test]
    fn centre_index_is_the_ceiling_of_v_minus_a_half_clamped() {
        for v in [
            -3.0, -0.2, 0.0, 0.49, 0.5, 0.51, 1.5, 2.25, 7.5, 9.99, 10.5, 11.0, 1e300,
        ] {
            let want = (v - 0.5f64).ceil().clamp(0.0, 10.0) as usize;
            assert_eq!(centre_index(v, 10), want, "{v}");
        }
        assert_eq!(centre_index(f64::NAN, 10), 0);
    }

    #[test]
    fn a_pixel_is_painted_exactly_when_its_centre_is_inside() {
        let pal = gif_palette();
        let mut x = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..200 {
            // Random polygons, convex or not, self-crossing, partly off the picture.
            let n = 3 + case % 9;
            let pts: Vec<[f64; 2]> = (0..n)
                .map(|_| [next() * 60.0 - 10.0, next() * 50.0 - 10.0])
                .collect();
            let mut pic = Indexed::new(40, 30, WHITE, pal);
            pic.fill(&pts, INK);
            let ink = pal.index(50, 50, 50);
            for y in 0..30 {
                for x in 0..40 {
                    let want = inside(&pts, [x as f64 + 0.5, y as f64 + 0.5]);
                    assert_eq!(
                        pic.px[y * 40 + x] == ink,
                        want,
                        "case {case}, pixel ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn a_translucent_colour_blends_with_what_is_under_it() {
        let pal = gif_palette();
        let glass: Rgba = [150, 156, 166, 150];
        let mut pic = Indexed::new(8, 8, WHITE, pal);
        pic.fill(&[[0.0, 0.0], [4.0, 0.0], [4.0, 8.0], [0.0, 8.0]], INK);
        pic.fill(&[[2.0, 0.0], [8.0, 0.0], [8.0, 8.0], [2.0, 8.0]], glass);
        let a = 150.0 / 255.0;
        let over = |under: [u8; 3]| {
            let c = [0, 1, 2]
                .map(|k| (f64::from(glass[k]) * a + f64::from(under[k]) * (1.0 - a)).round() as u8);
            pal.index(c[0], c[1], c[2])
        };
        let ink = pal.color(pal.index(50, 50, 50));
        let white = pal.color(pal.index(255, 255, 255));
        let row = &pic.px[3 * 8..4 * 8];
        assert_eq!(row[1], pal.index(50, 50, 50));
        assert_eq!(row[3], over(ink));
        assert_eq!(row[6], over(white));
        assert_ne!(row[3], row[6]);
    }

    #[test]
    fn a_kept_translucent_polygon_paints_what_a_fresh_one_does() {
        let pal = gif_palette();
        let glass: Rgba = [150, 156, 166, 150];
        let quad = [[3.3, 2.1], [35.6, 9.8], [30.2, 27.5], [6.1, 20.4]];
        let under = [[0.0, 0.0], [20.0, 0.0], [20.0, 30.0], [0.0, 30.0]];
        let draw = |pic: &mut Indexed, shift: f64| {
            pic.clear(WHITE);
            let moved: Vec<[f64; 2]> = under.iter().map(|p| [p[0] + shift, p[1]]).collect();
            pic.fill(&moved, INK);
            pic.fill(&quad, glass);
        };
        // One picture reused over frames (the glass's spans kept after the first), against
        // a fresh picture per frame; what is under the glass changes from frame to frame.
        let mut reused = Indexed::new(40, 30, WHITE, pal);
        for shift in [0.0, 7.5, 13.25] {
            draw(&mut reused, shift);
            let mut fresh = Indexed::new(40, 30, WHITE, pal);
            draw(&mut fresh, shift);
            assert!(reused.px == fresh.px, "shift {shift}");
        }
        assert_eq!(reused.kept.len(), 1);
    }

    #[test]
    fn a_thin_stroke_has_no_gaps_and_a_dash_pattern_its_period() {
        let pal = gif_palette();
        let ink = pal.index(50, 50, 50);
        for (a, b) in [
            ([2.3, 3.1], [57.9, 20.4]),
            ([5.5, 40.2], [31.7, 1.9]),
            ([1.2, 10.5], [58.8, 10.7]),
            ([30.1, 2.2], [29.4, 47.6]),
        ] {
            let mut pic = Indexed::new(60, 50, WHITE, pal);
            pic.stroke(&[a, b], false, pen(None));
            // Every column (or row, for steep lines) between the ends holds the line.
            let steep = (b[1] - a[1]).abs() > (b[0] - a[0]).abs();
            let (lo, hi) = if steep {
                (
                    a[1].min(b[1]).ceil() as usize,
                    a[1].max(b[1]).floor() as usize,
                )
            } else {
                (
                    a[0].min(b[0]).ceil() as usize,
                    a[0].max(b[0]).floor() as usize,
                )
            };
            for k in lo..hi {
                let hit = (0..if steep { 60 } else { 50 }).any(|j| {
                    let (x, y) = if steep { (j, k) } else { (k, j) };
                    pic.px[y * 60 + x] == ink
                });
                assert!(hit, "{a:?}–{b:?}: nothing at {k}");
            }
        }
        // A horizontal dashed line along a pixel row's centre: 4 on, 3 off.
        let mut pic = Indexed::new(40, 3, WHITE, pal);
        pic.stroke(&[[0.0, 1.5], [40.0, 1.5]], false, pen(Some([4.0, 3.0])));
        let row: Vec<bool> = pic.px[40..80].iter().map(|&p| p == ink).collect();
        for (x, &on) in row.iter().enumerate() {
            assert_eq!(on, x % 7 < 4, "pixel {x}");
        }
    }
}
