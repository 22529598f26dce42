//! Pictures of folded states: PNG (tiny-skia), SVG, and an animated GIF of the motion.
//!
//! An orthographic axonometric camera (azimuth/elevation, z up) projects the scene; facets
//! are drawn back to front by the depth of their centroid (painter's algorithm), filled
//! with a colour per side (front = the side whose normal is +z in the flat state) and
//! shaded by |n · l|, outlined in dark grey. The obstacle cylinder is a shaded,
//! translucent mesh sorted with the facets. Target points (red), the trajectory (green
//! polyline) and the gripping vertex with its path over the frames (black) are drawn on
//! top so they stay visible. With [`DesignMeta::second_arm`] the pattern rotated 180°
//! about z is drawn as well, in its own colours (exactly as before the scene existed); other
//! copies of [`DesignMeta::scene`] are turned about their axis. The scene's other obstacles
//! (spheres, boxes, half-spaces as a square of their plane, further cylinders, loaded
//! meshes) are translucent polygons like the cylinder, its containment boxes dashed
//! wireframes. The scale is fixed over all frames so an animation does not jump.

use rayon::prelude::*;
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

use super::palette::{
    AXES, BACK, BACK2, FRONT, FRONT2, OBSTACLE, OUTLINE, PROGRESS, Rgba, SHADE_MIN, TARGET,
    TRAJECTORY, WHITE,
};
pub use super::palette::{GifPalette, gif_palette};
use super::raster::{self, Canvas, Indexed, Pen};
use super::{DesignMeta, ExportError, Result, scene_polys, validate_meta, validate_pattern};
use crate::geom::{self, V3};
use crate::pattern::Pattern;

/// An orthographic camera looking at the origin from a direction given in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Angle of the viewing direction about +z, from +x (degrees).
    pub azimuth_deg: f64,
    /// Angle of the viewing direction above the xy-plane (degrees), in (−90, 90).
    pub elevation_deg: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            azimuth_deg: -60.0,
            elevation_deg: 25.0,
        }
    }
}

impl Camera {
    /// Screen right, screen up, and the direction toward the viewer (all unit vectors).
    pub fn basis(&self) -> (V3, V3, V3) {
        let (az, el) = (
            self.azimuth_deg.to_radians(),
            self.elevation_deg.to_radians(),
        );
        let dir = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
        let right = geom::normalize(geom::cross([0.0, 0.0, 1.0], dir)).unwrap_or([1.0, 0.0, 0.0]);
        let up = geom::cross(dir, right);
        (right, up, dir)
    }
}

/// The colour as the canvases take it.
fn rgba(c: Rgba) -> raster::Rgba {
    [c.0, c.1, c.2, c.3]
}

/// tiny-skia, anti-aliased: the PNG pictures.
struct Skia<'a>(&'a mut Pixmap);

impl Skia<'_> {
    fn paint(c: raster::Rgba) -> Paint<'static> {
        let mut p = Paint::default();
        p.set_color_rgba8(c[0], c[1], c[2], c[3]);
        p.anti_alias = true;
        p
    }

    fn path(pts: &[[f64; 2]], close: bool) -> Option<tiny_skia::Path> {
        let mut pb = PathBuilder::new();
        for (i, q) in pts.iter().enumerate() {
            if i == 0 {
                pb.move_to(q[0] as f32, q[1] as f32);
            } else {
                pb.line_to(q[0] as f32, q[1] as f32);
            }
        }
        if close {
            pb.close();
        }
        pb.finish()
    }
}

impl Canvas for Skia<'_> {
    fn size(&self) -> (u32, u32) {
        (self.0.width(), self.0.height())
    }

    fn fill(&mut self, pts: &[[f64; 2]], color: raster::Rgba) {
        if let Some(path) = Self::path(pts, true) {
            let paint = Self::paint(color);
            (self.0).fill_path(
                &path,
                &paint,
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    fn stroke(&mut self, pts: &[[f64; 2]], close: bool, pen: Pen) {
        let Pen { color, width, dash } = pen;
        let Some(path) = Self::path(pts, close) else {
            return;
        };
        let st = Stroke {
            width: width as f32,
            dash: dash
                .and_then(|[on, off]| tiny_skia::StrokeDash::new(vec![on as f32, off as f32], 0.0)),
            ..Stroke::default()
        };
        (self.0).stroke_path(&path, &Self::paint(color), &st, Transform::identity(), None);
    }

    fn dot(&mut self, c: [f64; 2], r: f64, fill: raster::Rgba, ring: raster::Rgba) {
        if let Some(path) = PathBuilder::from_circle(c[0] as f32, c[1] as f32, r as f32) {
            let t = Transform::identity();
            (self.0).fill_path(&path, &Self::paint(fill), FillRule::Winding, t, None);
            let st = Stroke {
                width: 1.0,
                ..Stroke::default()
            };
            (self.0).stroke_path(&path, &Self::paint(ring), &st, t, None);
        }
    }
}

/// A 2D item of a picture, in world-projected coordinates (not yet fitted to pixels).
#[derive(Clone, Debug)]
enum Item {
    Polygon {
        pts: Vec<[f64; 2]>,
        fill: Rgba,
        outline: Option<Rgba>,
    },
    Polyline {
        pts: Vec<[f64; 2]>,
        color: Rgba,
        width: f64,
        dashed: bool,
    },
    Dot {
        at: [f64; 2],
        color: Rgba,
        radius: f64,
    },
}

/// A design ready to be drawn: pattern, metadata and camera, with a fixed fit to the image.
pub struct Scene<'a> {
    pattern: &'a Pattern,
    meta: &'a DesignMeta,
    /// [`Camera::basis`] of the scene's camera, computed once: every projected point needs it.
    basis: (V3, V3, V3),
    lo: [f64; 2],
    hi: [f64; 2],
    /// Centre and radius of a ball holding the arm in every state (where a half-space's
    /// square is drawn, and how large).
    extent: (V3, f64),
}

fn mirror_z(p: V3) -> V3 {
    [-p[0], -p[1], p[2]]
}

fn cylinder_polys(c: &super::Cylinder, segments: usize) -> Vec<Vec<V3>> {
    let axis = geom::sub(c.b, c.a);
    let Some(w) = geom::normalize(axis) else {
        return Vec::new();
    };
    let helper = if w[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = geom::normalize(geom::cross(w, helper)).unwrap_or([0.0, 0.0, 1.0]);
    let v = geom::cross(w, u);
    let ring = |base: V3, k: usize| {
        let th = std::f64::consts::TAU * k as f64 / segments as f64;
        geom::add(
            base,
            geom::add(
                geom::scale(u, c.radius * th.cos()),
                geom::scale(v, c.radius * th.sin()),
            ),
        )
    };
    let mut polys = Vec::new();
    for k in 0..segments {
        polys.push(vec![
            ring(c.a, k),
            ring(c.a, k + 1),
            ring(c.b, k + 1),
            ring(c.b, k),
        ]);
    }
    polys.push((0..segments).rev().map(|k| ring(c.a, k)).collect());
    polys.push((0..segments).map(|k| ring(c.b, k)).collect());
    polys
}

impl<'a> Scene<'a> {
    /// Prepare a scene; validates the pattern and metadata.
    pub fn new(pattern: &'a Pattern, meta: &'a DesignMeta, camera: Camera) -> Result<Scene<'a>> {
        validate_pattern(pattern)?;
        validate_meta(meta, pattern)?;
        if !(camera.elevation_deg.abs() < 90.0 && camera.azimuth_deg.is_finite()) {
            return Err(ExportError::invalid(
                "camera",
                "elevation must be in (−90°, 90°) and azimuth finite",
            ));
        }
        let mut s = Scene {
            pattern,
            meta,
            basis: camera.basis(),
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
            extent: ([0.0; 3], 0.0),
        };
        let mut pts: Vec<V3> = Vec::new();
        let states: Vec<Vec<V3>> = if pattern.frames.is_empty() {
            vec![pattern.flat_coords()]
        } else {
            pattern.frames.iter().map(|f| f.coords.clone()).collect()
        };
        for st in &states {
            pts.extend(st.iter().copied());
            if meta.second_arm() {
                pts.extend(st.iter().map(|&p| mirror_z(p)));
            }
        }
        s.extent = super::scene_mesh::extent(&pts);
        let copies = &meta.scene.copies;
        if !meta.second_arm() {
            for st in &states {
                for k in 1..copies.n {
                    pts.extend(st.iter().map(|&p| copies.apply(k, p)));
                }
            }
        }
        pts.extend(meta.targets.iter().map(|t| t.p));
        pts.extend(meta.trajectory.iter().copied());
        if let Some(c) = &meta.first_cylinder() {
            pts.extend(cylinder_polys(c, 24).into_iter().flatten());
        }
        let (near, half) = (s.extent.0, s.extent.1.max(0.5));
        pts.extend(
            scene_polys::obstacle_polys(meta, near, half)
                .into_iter()
                .flatten(),
        );
        pts.extend(scene_polys::containment_edges(meta).into_iter().flatten());
        for p in pts {
            let q = s.project(p);
            for ((lo, hi), x) in s.lo.iter_mut().zip(s.hi.iter_mut()).zip(q) {
                *lo = lo.min(x);
                *hi = hi.max(x);
            }
        }
        Ok(s)
    }

    fn project(&self, p: V3) -> [f64; 2] {
        let (r, u, _) = self.basis;
        [geom::dot(p, r), geom::dot(p, u)]
    }

    fn depth(&self, p: V3) -> f64 {
        geom::dot(p, self.basis.2)
    }

    fn coords(&self, frame: Option<usize>) -> Vec<V3> {
        match frame.and_then(|k| self.pattern.frames.get(k)) {
            Some(f) => f.coords.clone(),
            None => self.pattern.flat_coords(),
        }
    }

    /// The items of one state, back to front.
    fn items(&self, frame: Option<usize>) -> Vec<Item> {
        let (_, up, dir) = self.basis;
        let light = geom::normalize(geom::add(dir, geom::scale(up, 0.6))).unwrap_or(dir);
        let coords = self.coords(frame);
        let mut polys: Vec<(f64, Item)> = Vec::new();
        let mut add_poly = |pts3: &[V3], front: Rgba, back: Rgba, outline: Option<Rgba>| {
            let n = geom::normalize(geom::newell_normal(pts3)).unwrap_or(dir);
            let facing = geom::dot(n, dir) >= 0.0;
            let base = if facing { front } else { back };
            let k = SHADE_MIN + (1.0 - SHADE_MIN) * geom::dot(n, light).abs();
            let c = pts3.iter().fold([0.0; 3], |a, &p| geom::add(a, p));
            let depth = self.depth(geom::scale(c, 1.0 / pts3.len() as f64));
            polys.push((
                depth,
                Item::Polygon {
                    pts: pts3.iter().map(|&p| self.project(p)).collect(),
                    fill: base.shade(k),
                    outline,
                },
            ));
        };
        for f in &self.pattern.faces {
            let pts: Vec<V3> = f.iter().map(|&v| coords[v]).collect();
            add_poly(&pts, FRONT, BACK, Some(OUTLINE));
            if self.meta.second_arm() {
                // Rotating by 180° about z keeps orientation, so the normal rule holds.
                let pts2: Vec<V3> = pts.iter().map(|&p| mirror_z(p)).collect();
                add_poly(&pts2, FRONT2, BACK2, Some(OUTLINE));
            } else {
                // Any other copies: turned about their axis (rotations keep orientation).
                let copies = &self.meta.scene.copies;
                for k in 1..copies.n {
                    let pk: Vec<V3> = pts.iter().map(|&p| copies.apply(k, p)).collect();
                    add_poly(&pk, FRONT2, BACK2, Some(OUTLINE));
                }
            }
        }
        if let Some(c) = &self.meta.first_cylinder() {
            for poly in cylinder_polys(c, 24) {
                add_poly(&poly, OBSTACLE, OBSTACLE, None);
            }
        }
        let (near, half) = (self.extent.0, self.extent.1.max(0.5));
        for poly in scene_polys::obstacle_polys(self.meta, near, half) {
            add_poly(&poly, OBSTACLE, OBSTACLE, None);
        }
        polys.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut items: Vec<Item> = polys.into_iter().map(|(_, it)| it).collect();
        for e in scene_polys::containment_edges(self.meta) {
            items.push(Item::Polyline {
                pts: vec![self.project(e[0]), self.project(e[1])],
                color: OUTLINE,
                width: 1.0,
                dashed: true,
            });
        }

        if self.meta.trajectory.len() >= 2 {
            items.push(Item::Polyline {
                pts: self
                    .meta
                    .trajectory
                    .iter()
                    .map(|&p| self.project(p))
                    .collect(),
                color: TRAJECTORY,
                width: 2.0,
                dashed: false,
            });
        }
        // Validated as 1..=n: the vertex name vK is index K − 1.
        if let Some(g) = self.meta.gripping_vertex.map(|g| g - 1) {
            if self.pattern.frames.len() >= 2 {
                items.push(Item::Polyline {
                    pts: self
                        .pattern
                        .frames
                        .iter()
                        .map(|f| self.project(f.coords[g]))
                        .collect(),
                    color: OUTLINE,
                    width: 1.0,
                    dashed: true,
                });
            }
            items.push(Item::Dot {
                at: self.project(coords[g]),
                color: OUTLINE,
                radius: 3.0,
            });
        }
        for t in &self.meta.targets {
            items.push(Item::Dot {
                at: self.project(t.p),
                color: TARGET,
                radius: 4.0,
            });
        }
        items
    }

    /// World-projected point → pixel, fitted with a margin; y grows downward.
    fn fit(&self, size: (u32, u32)) -> impl Fn([f64; 2]) -> [f64; 2] + use<> {
        let (w, h) = (size.0 as f64, size.1 as f64);
        let margin = 0.06 * w.min(h);
        let span = [
            (self.hi[0] - self.lo[0]).max(1e-9),
            (self.hi[1] - self.lo[1]).max(1e-9),
        ];
        let s = ((w - 2.0 * margin) / span[0]).min((h - 2.0 * margin) / span[1]);
        let cx = 0.5 * (self.lo[0] + self.hi[0]);
        let cy = 0.5 * (self.lo[1] + self.hi[1]);
        move |p: [f64; 2]| [0.5 * w + s * (p[0] - cx), 0.5 * h - s * (p[1] - cy)]
    }

    fn check_size(size: (u32, u32)) -> Result<()> {
        if !(16..=4096).contains(&size.0) || !(16..=4096).contains(&size.1) {
            return Err(ExportError::invalid(
                "image size",
                format!(
                    "{}×{} pixels; each side must be in 16..=4096",
                    size.0, size.1
                ),
            ));
        }
        Ok(())
    }

    /// Draw one state (`frame` index into [`Pattern::frames`]; `None` = flat) to a pixmap.
    pub fn pixmap(&self, frame: Option<usize>, size: (u32, u32)) -> Result<Pixmap> {
        Self::check_size(size)?;
        let mut pm = Pixmap::new(size.0, size.1)
            .ok_or_else(|| ExportError::Image("cannot allocate the image".into()))?;
        self.draw(&mut pm, frame);
        Ok(pm)
    }

    /// Draw one state, anti-aliased, over the whole of `pm` (cleared to white first), so a
    /// caller drawing many states can reuse one pixmap.
    fn draw(&self, pm: &mut Pixmap, frame: Option<usize>) {
        pm.fill(Color::WHITE);
        self.draw_on(&mut Skia(pm), frame);
    }

    /// One state as the GIF draws it: hard edges, straight into palette entries, over the
    /// whole of `pic` (cleared to white first; reused, it keeps its blend tables).
    fn draw_indexed(&self, pic: &mut Indexed, frame: Option<usize>) {
        pic.clear(rgba(WHITE));
        self.draw_on(pic, frame);
    }

    /// The GIF's frame `k` of `n`: pattern frame `frame_index`, hard-edged, with the
    /// progress bar.
    fn gif_frame(&self, pic: &mut Indexed, frame_index: usize, k: usize, n: usize) {
        self.draw_indexed(pic, Some(frame_index));
        draw_progress(pic, k, n);
    }

    /// The GIF's frames as palette entries, drawn one after the other (what
    /// [`Scene::gif_and_pngs`] draws in parallel; for `foldsynth bench export`).
    pub(crate) fn gif_frames(&self, size: (u32, u32), max_frames: usize) -> Result<Vec<Vec<u8>>> {
        Self::check_size(size)?;
        let picked = super::picked_frames(self.pattern.frames.len(), max_frames.max(2));
        let mut pic = Indexed::new(size.0, size.1, rgba(WHITE), gif_palette());
        Ok(picked
            .iter()
            .enumerate()
            .map(|(k, &f)| {
                self.gif_frame(&mut pic, f, k, picked.len());
                pic.take()
            })
            .collect())
    }

    /// Draw one state's items and the axes on `canvas` (fitted to its size).
    fn draw_on(&self, canvas: &mut impl Canvas, frame: Option<usize>) {
        let size = canvas.size();
        let fit = self.fit(size);
        let px = |pts: &[[f64; 2]]| -> Vec<[f64; 2]> { pts.iter().map(|&p| fit(p)).collect() };
        for item in self.items(frame) {
            match item {
                Item::Polygon { pts, fill, outline } => {
                    let q = px(&pts);
                    canvas.fill(&q, rgba(fill));
                    if let Some(o) = outline {
                        canvas.stroke(
                            &q,
                            true,
                            Pen {
                                color: rgba(o),
                                width: 1.0,
                                dash: None,
                            },
                        );
                    }
                }
                Item::Polyline {
                    pts,
                    color,
                    width,
                    dashed,
                } => canvas.stroke(
                    &px(&pts),
                    false,
                    Pen {
                        color: rgba(color),
                        width,
                        dash: dashed.then_some([4.0, 3.0]),
                    },
                ),
                Item::Dot { at, color, radius } => {
                    canvas.dot(fit(at), radius, rgba(color), rgba(WHITE));
                }
            }
        }
        for (a, b, c, _) in self.axes_lines(size) {
            canvas.stroke(
                &[a, b],
                false,
                Pen {
                    color: rgba(c),
                    width: 2.0,
                    dash: None,
                },
            );
        }
    }

    fn axes_lines(&self, size: (u32, u32)) -> Vec<([f64; 2], [f64; 2], Rgba, &'static str)> {
        let (r, u, _) = self.basis;
        let origin = [24.0, size.1 as f64 - 24.0];
        let axes = [
            ([1.0, 0.0, 0.0], AXES[0], "x"),
            ([0.0, 1.0, 0.0], AXES[1], "y"),
            ([0.0, 0.0, 1.0], AXES[2], "z"),
        ];
        axes.iter()
            .map(|&(a, c, name)| {
                let end = [
                    origin[0] + 16.0 * geom::dot(a, r),
                    origin[1] - 16.0 * geom::dot(a, u),
                ];
                (origin, end, c, name)
            })
            .collect()
    }

    /// One state as PNG bytes.
    pub fn png(&self, frame: Option<usize>, size: (u32, u32)) -> Result<Vec<u8>> {
        encode_png(&self.pixmap(frame, size)?)
    }

    /// The motion as an animated GIF (looping, with a pause at the end and a progress bar
    /// along the bottom edge): at most `max_frames` frames, evenly picked over the
    /// pattern's frames (first and last included). `delay_cs` is the frame delay in 1/100 s.
    ///
    /// The frames are drawn without anti-aliasing (the PNG pictures keep it). The colours
    /// are the renderer's own ([`gif_palette`]: one global palette, no per-frame
    /// quantization). After the first frame each frame holds only the rectangle
    /// that changed, with unchanged pixels in it transparent (disposal "keep"), so a
    /// viewer composes exactly the full pictures while LZW reads far fewer, far more
    /// repetitive bytes ([`super::lzw`], with its fast path for runs). Frames are drawn
    /// and compressed in parallel; only the byte stream is written in order.
    pub fn gif(&self, size: (u32, u32), delay_cs: u16, max_frames: usize) -> Result<Vec<u8>> {
        Ok(self.gif_and_pngs(size, delay_cs, max_frames, &[])?.0)
    }

    /// [`Scene::gif`] and [`Scene::png`] of each state in `pictures` (indices into the
    /// pattern's frames), on the worker that draws the state's animation frame. The PNGs
    /// come back in the order of `pictures`.
    pub fn gif_and_pngs(
        &self,
        size: (u32, u32),
        delay_cs: u16,
        max_frames: usize,
        pictures: &[usize],
    ) -> Result<(Vec<u8>, Vec<Vec<u8>>)> {
        Self::check_size(size)?;
        let total = self.pattern.frames.len();
        if total == 0 {
            return Err(ExportError::invalid(
                "pattern.frames",
                "empty: nothing to animate",
            ));
        }
        let picked = super::picked_frames(total, max_frames.max(2));
        let n = picked.len();
        let palette = gif_palette();
        let drawn: Vec<(Vec<u8>, Option<Vec<u8>>)> = picked
            .par_iter()
            .enumerate()
            // Per worker one palette picture, and one pixmap for the PNG pictures, redrawn
            // for each of its frames.
            .map_init(
                || {
                    (
                        Indexed::new(size.0, size.1, rgba(WHITE), palette),
                        None::<Pixmap>,
                    )
                },
                |(pic, pm), (k, &frame_index)| {
                    let png = if pictures.contains(&frame_index) {
                        if pm.is_none() {
                            *pm = Pixmap::new(size.0, size.1);
                        }
                        let pm = pm.as_mut().ok_or_else(|| {
                            ExportError::Image("cannot allocate the image".into())
                        })?;
                        self.draw(pm, Some(frame_index));
                        Some(encode_png(pm)?)
                    } else {
                        None
                    };
                    self.gif_frame(pic, frame_index, k, n);
                    Ok((pic.take(), png))
                },
            )
            .collect::<Result<_>>()?;
        let (w, h) = (size.0 as usize, size.1 as usize);
        let frames: Vec<gif::Frame<'static>> = (0..n)
            .into_par_iter()
            .map(|k| {
                let cur = &drawn[k].0;
                let mut frame = match (k.checked_sub(1), palette.transparent()) {
                    (Some(prev), Some(t)) => delta_frame(&drawn[prev].0, cur, w, h, t),
                    _ => gif::Frame::from_indexed_pixels(
                        size.0 as u16,
                        size.1 as u16,
                        cur.clone(),
                        None,
                    ),
                };
                frame.dispose = gif::DisposalMethod::Keep;
                frame.delay = if k + 1 == n {
                    delay_cs.saturating_mul(8).max(50)
                } else {
                    delay_cs
                };
                frame.buffer = std::borrow::Cow::Owned(super::lzw::encode(&frame.buffer));
                frame
            })
            .collect();
        let img = |e: gif::EncodingError| ExportError::Image(e.to_string());
        let mut enc = gif::Encoder::new(Vec::new(), size.0 as u16, size.1 as u16, &palette.rgb)
            .map_err(img)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(img)?;
        for frame in &frames {
            enc.write_lzw_pre_encoded_frame(frame).map_err(img)?;
        }
        let gif = enc.into_inner().map_err(img)?;
        let pngs = pictures
            .iter()
            .map(|&f| match picked.iter().position(|&q| q == f) {
                Some(k) => match &drawn[k].1 {
                    Some(png) => Ok(png.clone()),
                    None => self.png(Some(f), size),
                },
                None => self.png(Some(f), size),
            })
            .collect::<Result<_>>()?;
        Ok((gif, pngs))
    }

    /// One state as a standalone SVG document (vector version of [`Scene::png`]).
    pub fn svg(&self, frame: Option<usize>, size: (u32, u32)) -> String {
        let mut s = format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{}",
            self.svg_element(frame, size)
        );
        s.push('\n');
        s
    }

    /// One state as an `<svg>` element without XML prolog (for inlining into HTML).
    pub fn svg_element(&self, frame: Option<usize>, size: (u32, u32)) -> String {
        let fit = self.fit(size);
        let pts_attr = |pts: &[[f64; 2]]| -> String {
            pts.iter()
                .map(|&p| {
                    let q = fit(p);
                    format!("{:.2},{:.2}", q[0], q[1])
                })
                .collect::<Vec<_>>()
                .join(" ")
        };
        let mut out = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n<rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>\n",
            w = size.0,
            h = size.1
        );
        for item in self.items(frame) {
            match item {
                Item::Polygon { pts, fill, outline } => {
                    let stroke = match outline {
                        Some(o) => format!(
                            " stroke=\"{}\" stroke-width=\"1\" stroke-linejoin=\"round\"",
                            o.hex()
                        ),
                        None => String::new(),
                    };
                    out += &format!(
                        "<polygon points=\"{}\" fill=\"{}\" fill-opacity=\"{:.3}\"{stroke}/>\n",
                        pts_attr(&pts),
                        fill.hex(),
                        fill.opacity()
                    );
                }
                Item::Polyline {
                    pts,
                    color,
                    width,
                    dashed,
                } => {
                    out += &format!(
                        "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{width}\"{}/>\n",
                        pts_attr(&pts),
                        color.hex(),
                        if dashed {
                            " stroke-dasharray=\"4 3\""
                        } else {
                            ""
                        }
                    );
                }
                Item::Dot { at, color, radius } => {
                    let q = fit(at);
                    out += &format!(
                        "<circle cx=\"{:.2}\" cy=\"{:.2}\" r=\"{radius}\" fill=\"{}\" stroke=\"#ffffff\"/>\n",
                        q[0],
                        q[1],
                        color.hex()
                    );
                }
            }
        }
        for (a, b, c, name) in self.axes_lines(size) {
            out += &format!(
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" stroke-width=\"2\"/><text x=\"{:.1}\" y=\"{:.1}\" font-family=\"sans-serif\" font-size=\"10\" fill=\"{}\">{name}</text>\n",
                a[0],
                a[1],
                b[0],
                b[1],
                c.hex(),
                b[0] + 2.0,
                b[1] - 2.0,
                c.hex()
            );
        }
        let label = match frame.and_then(|k| self.pattern.frames.get(k)) {
            Some(f) => format!("t = {:.4}", f.t),
            None => "flat".into(),
        };
        out += &format!(
            "<text x=\"8\" y=\"16\" font-family=\"sans-serif\" font-size=\"13\" fill=\"#333333\">{label}</text>\n</svg>"
        );
        out
    }
}

/// A drawn picture as PNG bytes: RGB when every pixel is opaque (always, on the white
/// background; the same colours as RGBA, a quarter fewer bytes to compress), with the
/// `png` crate's fast DEFLATE (fdeflate): several times quicker than the default level
/// for files about a quarter larger.
pub(crate) fn encode_png(pm: &Pixmap) -> Result<Vec<u8>> {
    if !pm.pixels().iter().all(|p| p.alpha() == 255) {
        return pm
            .encode_png()
            .map_err(|e| ExportError::Image(e.to_string()));
    }
    // Opaque: premultiplied RGBA equals straight RGBA, so dropping alpha is exact.
    let mut rgb = vec![0u8; pm.data().len() / 4 * 3];
    for (o, px) in rgb.chunks_exact_mut(3).zip(pm.data().chunks_exact(4)) {
        o.copy_from_slice(&px[..3]);
    }
    let mut out = Vec::new();
    let img = |e: png::EncodingError| ExportError::Image(e.to_string());
    let mut enc = png::Encoder::new(&mut out, pm.width(), pm.height());
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Balanced);
    let mut writer = enc.write_header().map_err(img)?;
    writer.write_image_data(&rgb).map_err(img)?;
    writer.finish().map_err(img)?;
    Ok(out)
}

/// The GIF's progress bar along the bottom edge: frame `k` of `n` (0-based) fills k/(n − 1)
/// of the width (at least a pixel), 4 pixels high.
fn draw_progress(pic: &mut Indexed, k: usize, n: usize) {
    let (w, h) = pic.size();
    let (w, h) = (w as f64, h as f64);
    let frac = if n > 1 {
        k as f64 / (n - 1) as f64
    } else {
        1.0
    };
    let x = (w * frac).max(1.0);
    pic.fill(
        &[[0.0, h - 4.0], [x, h - 4.0], [x, h], [0.0, h]],
        rgba(PROGRESS),
    );
}

/// The GIF frame that turns picture `prev` into `cur` (both `w`×`h` palette indices) when
/// drawn over it: the bounding rectangle of the changed pixels, unchanged ones inside it
/// set to `transparent` (an index neither picture uses). No change: one transparent pixel.
pub(crate) fn delta_frame(
    prev: &[u8],
    cur: &[u8],
    w: usize,
    h: usize,
    transparent: u8,
) -> gif::Frame<'static> {
    // The rectangle so far: rows top..=bottom, columns left..end. A row only widens it,
    // so only the parts outside it are searched (compared as slices first).
    let (mut top, mut bottom, mut left, mut end) = (h, 0, w, 0);
    for y in 0..h {
        let (a, b) = (&prev[y * w..(y + 1) * w], &cur[y * w..(y + 1) * w]);
        if a == b {
            continue;
        }
        top = top.min(y);
        bottom = y;
        if a[..left] != b[..left] {
            left = a.iter().zip(b).position(|(p, q)| p != q).unwrap_or(left);
        }
        let from = end.max(left);
        if a[from..] != b[from..] {
            let back = a[from..]
                .iter()
                .rev()
                .zip(b[from..].iter().rev())
                .position(|(p, q)| p != q)
                .unwrap_or(0);
            end = w - back;
        }
    }
    let right = end.saturating_sub(1);
    if top > bottom {
        return gif::Frame::from_indexed_pixels(1, 1, vec![transparent], Some(transparent));
    }
    let (fw, fh) = (right - left + 1, bottom - top + 1);
    // Written into a sized buffer row by row (a loop the compiler vectorizes).
    let mut buf = vec![0u8; fw * fh];
    for (y, out) in (top..=bottom).zip(buf.chunks_exact_mut(fw)) {
        let row = y * w + left..y * w + right + 1;
        for ((o, &p), &q) in out.iter_mut().zip(&prev[row.clone()]).zip(&cur[row]) {
            *o = if p == q { transparent } else { q };
        }
    }
    let mut frame = gif::Frame::from_indexed_pixels(fw as u16, fh as u16, buf, Some(transparent));
    frame.left = left as u16;
    frame.top = top as u16;
    frame
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::samples;

    #[test]
    fn camera_basis_is_orthonormal_and_right_handed() {
        for (az, el) in [(-60.0, 25.0), (0.0, 0.0), (135.0, -40.0)] {
            let (r, u, d) = Camera {
                azimuth_deg: az,
                elevation_deg: el,
            }
            .basis();
            for (a, b) in [(r, u), (u, d), (r, d)] {
                assert!(geom::dot(a, b).abs() < 1e-12);
            }
            for a in [r, u, d] {
                assert!((geom::norm(a) - 1.0).abs() < 1e-12);
            }
            // right × up points toward the viewer: a right-handed screen frame.
            assert!(geom::dist(geom::cross(r, u), d) < 1e-12);
            // z projects upward on screen for |elevation| < 90°.
            assert!(u[2] > 0.0);
        }
    }

    /// The GIF's frames composed as a viewer does (each image drawn over the canvas at its
    /// offset, transparent pixels leaving the canvas as it was), as palette indices.
    fn composed_frames(bytes: &[u8]) -> Vec<(u16, Vec<u8>)> {
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::Indexed);
        let mut dec = opts.read_info(bytes).unwrap();
        let w = usize::from(dec.width());
        let mut canvas = vec![0u8; w * usize::from(dec.height())];
        let mut out = Vec::new();
        while let Some(f) = dec.read_next_frame().unwrap() {
            assert_eq!(f.dispose, gif::DisposalMethod::Keep);
            let fw = usize::from(f.width);
            for (i, &px) in f.buffer.iter().enumerate() {
                if Some(px) != f.transparent {
                    let (x, y) = (usize::from(f.left) + i % fw, usize::from(f.top) + i / fw);
                    canvas[y * w + x] = px;
                }
            }
            out.push((f.delay, canvas.clone()));
        }
        out
    }

    #[test]
    fn gif_frames_are_the_pictures_in_the_palette() {
        let p = samples::single_crease(2.0, 20);
        let meta = DesignMeta::default();
        let scene = Scene::new(&p, &meta, Camera::default()).unwrap();
        let pal = gif_palette();
        let bytes = scene.gif((96, 72), 4, 5).unwrap();
        let picked = super::super::picked_frames(p.frames.len(), 5);
        let frames = composed_frames(&bytes);
        assert_eq!(frames.len(), picked.len());
        for (k, (_, canvas)) in frames.iter().enumerate() {
            // Composed, each frame is exactly its hard-edged drawing with the progress bar,
            // although frames after the first hold only what changed.
            let mut pic = Indexed::new(96, 72, rgba(WHITE), pal);
            scene.draw_indexed(&mut pic, Some(picked[k]));
            draw_progress(&mut pic, k, picked.len());
            assert_eq!(*canvas, pic.px, "frame {k}");
            // And it is the anti-aliased picture in the palette's colours wherever the
            // picture is flat (a pixel and its 8 neighbours alike; the progress bar's rows
            // left out): the two drawings differ only along edges.
            let pm = scene.pixmap(Some(picked[k]), (96, 72)).unwrap();
            let rgb = |x: usize, y: usize| {
                let c = pm.pixel(x as u32, y as u32).unwrap();
                [c.red(), c.green(), c.blue()]
            };
            let mut flat = 0;
            for y in 1..72 - 5 {
                for x in 1..95 {
                    let c = rgb(x, y);
                    if (0..9).any(|j| rgb(x + j % 3 - 1, y + j / 3 - 1) != c) {
                        continue;
                    }
                    flat += 1;
                    let got = pal.color(canvas[y * 96 + x]);
                    let err = (0..3).map(|j| got[j].abs_diff(c[j])).max().unwrap_or(0);
                    assert!(err <= 12, "frame {k}, pixel ({x}, {y}): {got:?} for {c:?}");
                }
            }
            assert!(flat > 96 * 72 / 2, "frame {k}: only {flat} flat pixels");
        }
    }

    #[test]
    fn a_delta_frame_is_the_changed_rectangle() {
        let (w, h, t) = (6, 5, 255u8);
        let prev = vec![1u8; w * h];
        let mut cur = prev.clone();
        cur[w + 2] = 7; // (2, 1)
        cur[3 * w + 4] = 8; // (4, 3)
        cur[3 * w + 3] = 1; // unchanged inside the rectangle
        let f = delta_frame(&prev, &cur, w, h, t);
        assert_eq!((f.left, f.top, f.width, f.height), (2, 1, 3, 3));
        assert_eq!(f.transparent, Some(t));
        assert_eq!(&*f.buffer, &[7, t, t, t, t, t, t, t, 8]);
        let same = delta_frame(&prev, &prev, w, h, t);
        assert_eq!((same.width, same.height, &*same.buffer), (1, 1, &[t][..]));
    }

    #[test]
    fn a_delta_frame_is_the_tight_rectangle_of_random_changes() {
        let (w, h, t) = (37, 23, 255u8);
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move |n: usize| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % n as u64) as usize
        };
        for case in 0..300 {
            let prev: Vec<u8> = (0..w * h).map(|_| next(4) as u8).collect();
            let mut cur = prev.clone();
            for _ in 0..next(6) {
                let i = next(w * h);
                cur[i] = (cur[i] + 1 + next(3) as u8) % 5;
            }
            let f = delta_frame(&prev, &cur, w, h, t);
            let changed: Vec<usize> = (0..w * h).filter(|&i| prev[i] != cur[i]).collect();
            if changed.is_empty() {
                assert_eq!((f.width, f.height), (1, 1), "case {case}");
                continue;
            }
            let xs = changed.iter().map(|i| i % w);
            let ys = changed.iter().map(|i| i / w);
            let (l, r) = (xs.clone().min().unwrap(), xs.max().unwrap());
            let (tp, b) = (ys.clone().min().unwrap(), ys.max().unwrap());
            assert_eq!(
                (f.left, f.top, f.width, f.height),
                (l as u16, tp as u16, (r - l + 1) as u16, (b - tp + 1) as u16),
                "case {case}"
            );
            // Drawn over the previous picture, the frame gives the current one.
            let mut canvas = prev.clone();
            for (i, &p) in f.buffer.iter().enumerate() {
                if p != t {
                    canvas[(tp + i / (r - l + 1)) * w + l + i % (r - l + 1)] = p;
                }
            }
            assert_eq!(canvas, cur, "case {case}");
        }
    }

    #[test]
    fn pngs_drawn_with_the_gif_are_the_pictures() {
        let p = samples::single_crease(2.0, 20);
        let meta = DesignMeta::default();
        let scene = Scene::new(&p, &meta, Camera::default()).unwrap();
        // Frame 3 is in the GIF (all 20 frames), frame 5 is not when only 5 are picked.
        for (max_frames, states) in [(60, vec![3, 19]), (5, vec![5, 19])] {
            let (_, pngs) = scene
                .gif_and_pngs((96, 72), 4, max_frames, &states)
                .unwrap();
            assert_eq!(pngs.len(), states.len());
            for (png, &k) in pngs.iter().zip(&states) {
                let img = Pixmap::decode_png(png).unwrap();
                let pm = scene.pixmap(Some(k), (96, 72)).unwrap();
                assert_eq!(img.data(), pm.data(), "state {k}");
            }
        }
    }

    #[test]
    fn picture_shows_the_sheet_and_the_targets() {
        let p = samples::single_crease(std::f64::consts::FRAC_PI_2, 3);
        let meta = DesignMeta {
            targets: vec![super::super::TargetPoint {
                p: [0.5, 0.0, 1.0],
                t: None,
            }],
            ..DesignMeta::default()
        };
        let scene = Scene::new(&p, &meta, Camera::default()).unwrap();
        let pm = scene.pixmap(Some(2), (200, 150)).unwrap();
        let px = |x: u32, y: u32| pm.pixel(x, y).unwrap();
        // The target's pixel is red.
        let fit = scene.fit((200, 150));
        let q = fit(scene.project([0.5, 0.0, 1.0]));
        let c = px(q[0].round() as u32, q[1].round() as u32);
        assert!(c.red() > 180 && c.green() < 80 && c.blue() < 80, "{c:?}");
        // Some pixels are paper-coloured (not white, not grey).
        let painted = pm.pixels().iter().filter(|c| c.red() != c.blue()).count();
        assert!(painted > 500);
        // A corner is background white.
        assert_eq!(px(199, 0).red(), 255);
    }
}
