//! The colours the renderer draws with and the GIF palette built from them.
//!
//! Both `render` (which draws in these colours) and `raster` (which draws straight into
//! palette entries) use them, so they live here, below both.

/// A colour of the renderer: straight RGB and an alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Rgba(pub(super) u8, pub(super) u8, pub(super) u8, pub(super) u8);

impl Rgba {
    /// The colour scaled by `k` (alpha kept).
    pub(super) fn shade(self, k: f64) -> Rgba {
        let f = |c: u8| (c as f64 * k).round().clamp(0.0, 255.0) as u8;
        Rgba(f(self.0), f(self.1), f(self.2), self.3)
    }
    /// `#rrggbb`, for SVG.
    pub(super) fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
    /// The alpha as a fraction.
    pub(super) fn opacity(self) -> f64 {
        self.3 as f64 / 255.0
    }
}

pub(super) const FRONT: Rgba = Rgba(242, 200, 121, 255);
pub(super) const BACK: Rgba = Rgba(127, 167, 217, 255);
pub(super) const FRONT2: Rgba = Rgba(232, 168, 124, 255);
pub(super) const BACK2: Rgba = Rgba(143, 185, 168, 255);
pub(super) const OBSTACLE: Rgba = Rgba(150, 156, 166, 150);
pub(super) const OUTLINE: Rgba = Rgba(50, 50, 50, 255);
pub(super) const WHITE: Rgba = Rgba(255, 255, 255, 255);
pub(super) const TARGET: Rgba = Rgba(220, 30, 30, 255);
pub(super) const TRAJECTORY: Rgba = Rgba(20, 150, 60, 255);
pub(super) const PROGRESS: Rgba = Rgba(80, 80, 80, 255);
pub(super) const AXES: [Rgba; 3] = [
    Rgba(200, 40, 40, 255),
    Rgba(40, 150, 40, 255),
    Rgba(40, 70, 200, 255),
];
/// Lightest shade of a facet (the renderer shades by `0.45 + 0.55·|n·light|`).
pub(super) const SHADE_MIN: f64 = 0.45;

/// The GIF palette: the colours this renderer draws with (every shade of the four paper
/// colours, the obstacle over white, greys for white, outline and the progress bar, the
/// accents and their blends with white, the papers' blends with the outline) and a coarse
/// colour cube for the anti-aliased rest, with a 32³ table from colour to index.
pub struct GifPalette {
    /// `[r, g, b]` per entry, 256 entries.
    pub rgb: Vec<u8>,
    lut: Vec<u8>,
    /// An entry the table never returns (the colour cube's black and white duplicate the
    /// greys', and the first of equals wins), so a GIF frame can use it as "transparent".
    transparent: Option<u8>,
}

impl GifPalette {
    /// The entry for a colour (nearest to the centre of its 32³ table cell).
    #[inline]
    pub fn index(&self, r: u8, g: u8, b: u8) -> u8 {
        self.lut[(usize::from(r >> 3) << 10) | (usize::from(g >> 3) << 5) | usize::from(b >> 3)]
    }

    /// The entry no colour maps to, used as the transparent index of the GIF's delta frames
    /// (`None` if every entry is used; then every frame is written whole).
    pub fn transparent(&self) -> Option<u8> {
        self.transparent
    }

    /// The colour of entry `i`.
    pub fn color(&self, i: u8) -> [u8; 3] {
        let i = 3 * usize::from(i);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    fn build() -> GifPalette {
        let mut cols: Vec<[u8; 3]> = Vec::with_capacity(256);
        let rgb = |c: Rgba| [c.0, c.1, c.2];
        let mix = |a: [u8; 3], b: [u8; 3], t: f64| {
            [0, 1, 2].map(|i| (a[i] as f64 * (1.0 - t) + b[i] as f64 * t).round() as u8)
        };
        let white = [255, 255, 255];
        let shades = |n: usize| {
            (0..n).map(move |i| SHADE_MIN + (1.0 - SHADE_MIN) * i as f64 / (n - 1) as f64)
        };
        for paper in [FRONT, BACK, FRONT2, BACK2] {
            cols.extend(shades(32).map(|k| rgb(paper.shade(k))));
        }
        let a = OBSTACLE.opacity();
        cols.extend(shades(12).map(|k| mix(white, rgb(OBSTACLE.shade(k)), a)));
        cols.extend((0..18).map(|i| {
            let v = (255.0 * i as f64 / 17.0).round() as u8;
            [v, v, v]
        }));
        for accent in [TARGET, TRAJECTORY, AXES[0], AXES[1], AXES[2]] {
            cols.push(rgb(accent));
            cols.push(mix(rgb(accent), white, 0.5));
        }
        for paper in [FRONT, BACK, FRONT2, BACK2] {
            cols.extend(shades(6).map(|k| mix(rgb(paper.shade(k)), rgb(OUTLINE), 0.5)));
        }
        for r in 0..4u8 {
            for g in 0..4u8 {
                for b in 0..4u8 {
                    cols.push([r * 85, g * 85, b * 85]);
                }
            }
        }
        debug_assert_eq!(cols.len(), 256);
        cols.truncate(256);
        let mut lut = vec![0u8; 1 << 15];
        for (cell, entry) in lut.iter_mut().enumerate() {
            let c = [(cell >> 10) & 31, (cell >> 5) & 31, cell & 31].map(|v| (v * 8 + 4) as i32);
            let d = |p: &[u8; 3]| (0..3).map(|i| (p[i] as i32 - c[i]).pow(2)).sum::<i32>();
            *entry = (0..cols.len()).min_by_key(|&i| d(&cols[i])).unwrap_or(0) as u8;
        }
        let mut used = [false; 256];
        for &i in &lut {
            used[usize::from(i)] = true;
        }
        let transparent = (0..=255u8).rev().find(|&i| !used[usize::from(i)]);
        GifPalette {
            rgb: cols.into_iter().flatten().collect(),
            lut,
            transparent,
        }
    }
}

/// The palette of every GIF this renderer writes (built once).
pub fn gif_palette() -> &'static GifPalette {
    static PALETTE: std::sync::OnceLock<GifPalette> = std::sync::OnceLock::new();
    PALETTE.get_or_init(GifPalette::build)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gif_palette_holds_the_renderers_colours() {
        let pal = gif_palette();
        assert_eq!(pal.rgb.len(), 3 * 256);
        let err = |c: [u8; 3]| {
            let e = pal.color(pal.index(c[0], c[1], c[2]));
            (0..3)
                .map(|i| (e[i] as i32 - c[i] as i32).abs())
                .max()
                .unwrap_or(0)
        };
        // A colour c is within 4√3 of its cell's centre m, and the entry q chosen for m is
        // no farther from m than the entry e nearest c: |q − c| ≤ |e − c| + 8√3. For an
        // entry e = c (< 14); for a shade of paper |e − c| ≤ √3·(half a step of 4.3 +
        // rounding 0.5) (< 19).
        for paper in [FRONT, BACK, FRONT2, BACK2] {
            for i in 0..=200 {
                let k = SHADE_MIN + (1.0 - SHADE_MIN) * i as f64 / 200.0;
                let c = paper.shade(k);
                assert!(err([c.0, c.1, c.2]) < 19, "{paper:?} at {k}");
            }
        }
        for c in [
            OUTLINE, TARGET, TRAJECTORY, PROGRESS, AXES[0], AXES[1], AXES[2],
        ] {
            assert!(err([c.0, c.1, c.2]) < 14, "{c:?}");
        }
        assert_eq!(pal.color(pal.index(255, 255, 255)), [255, 255, 255]);
    }

    #[test]
    fn the_transparent_entry_is_one_no_colour_maps_to() {
        let pal = gif_palette();
        let t = pal.transparent().expect("the palette has an unused entry");
        // Every cell of the 32³ table, i.e. every colour there is.
        for cell in 0..1usize << 15 {
            let (r, g, b) = (
                (cell >> 10) as u8,
                (cell >> 5 & 31) as u8,
                (cell & 31) as u8,
            );
            assert_ne!(pal.index(r << 3, g << 3, b << 3), t);
        }
    }
}
