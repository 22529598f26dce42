//! How a design is built from a sheet of finite thickness (issue 32): the `[fabrication]`
//! table of a task file and the options of `foldsynth fabricate`, as one validated value.
//!
//! ```toml
//! [fabrication]
//! thickness = 2.0        # mm: panel thickness
//! scale = 100.0          # mm per paper unit (G0's first crease = 1)
//! method = "tapered"     # volume trimming with tapered panels (Tachi 2011)
//! sides = "one"          # "one": panels on the +normal side of the sheet; "both": centred
//! hinge_gap = 0.5        # mm: the smallest gap cut between two panels at a crease
//! min_width = 2.0        # mm: the narrowest a trimmed panel may become
//! ```

/// The construction of thick panels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FabMethod {
    /// Volume trimming with tapered panels (Tachi, "Rigid-foldable thick origami", 2011):
    /// the hinge axes stay on the zero-thickness crease lines, each panel is its facet's
    /// slab, trimmed near each crease by the bisector of the closed wedge at the crease's
    /// largest fold angle, so the two panels meet there and not before.
    Tapered,
}

impl FabMethod {
    /// The names a task file or a command line may use.
    pub const NAMES: [&'static str; 1] = ["tapered"];

    /// The method called `name`, if any.
    pub fn from_name(name: &str) -> Option<FabMethod> {
        match name {
            "tapered" => Some(FabMethod::Tapered),
            _ => None,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            FabMethod::Tapered => "tapered",
        }
    }
}

/// Where the slab lies relative to the zero-thickness sheet (the hinge plane).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sides {
    /// The slab spans offsets `[0, thickness]` along each facet's normal (the normal of the
    /// flat sheet, +z, carried by the facet's motion).
    One,
    /// The slab spans `[−thickness/2, thickness/2]`: a laminate whose hinge layer is in the
    /// middle.
    Both,
}

impl Sides {
    /// The names a task file or a command line may use.
    pub const NAMES: [&'static str; 2] = ["one", "both"];

    /// The choice called `name`, if any.
    pub fn from_name(name: &str) -> Option<Sides> {
        match name {
            "one" => Some(Sides::One),
            "both" => Some(Sides::Both),
            _ => None,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Sides::One => "one",
            Sides::Both => "both",
        }
    }
}

/// Default `hinge_gap` in mm: a laser kerf and a little play.
pub const DEFAULT_HINGE_GAP_MM: f64 = 0.5;

/// Default `min_width` in mm.
pub const DEFAULT_MIN_WIDTH_MM: f64 = 2.0;

/// Largest thickness or scale accepted, in mm (10 m): beyond it a value is a typo.
pub const MAX_LENGTH_MM: f64 = 10_000.0;

/// A validated fabrication setting. Lengths are in mm; `scale` converts paper units to mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fabrication {
    /// Panel thickness, mm (finite, > 0).
    pub thickness: f64,
    /// mm per paper unit (finite, > 0).
    pub scale: f64,
    /// The construction.
    pub method: FabMethod,
    /// Where the slab lies.
    pub sides: Sides,
    /// Smallest gap between two panels at a crease, mm (finite, ≥ 0).
    pub hinge_gap: f64,
    /// Narrowest a trimmed panel may become, mm (finite, ≥ 0).
    pub min_width: f64,
}

impl Fabrication {
    /// Check every value; `Err((field, what is allowed))` names the first bad one.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let positive = |field: &'static str, v: f64| {
            if v.is_finite() && v > 0.0 && v <= MAX_LENGTH_MM {
                Ok(())
            } else {
                Err((
                    field,
                    format!("must be a number of mm in (0, {MAX_LENGTH_MM}], got {v}"),
                ))
            }
        };
        let non_negative = |field: &'static str, v: f64| {
            if v.is_finite() && (0.0..=MAX_LENGTH_MM).contains(&v) {
                Ok(())
            } else {
                Err((
                    field,
                    format!("must be a number of mm in [0, {MAX_LENGTH_MM}], got {v}"),
                ))
            }
        };
        positive("thickness", self.thickness)?;
        positive("scale", self.scale)?;
        non_negative("hinge_gap", self.hinge_gap)?;
        non_negative("min_width", self.min_width)
    }

    /// The thickness in paper units.
    pub fn thickness_units(&self) -> f64 {
        self.thickness / self.scale
    }

    /// The offsets `[lo, hi]` of the slab along a facet's normal, in paper units.
    pub fn slab_units(&self) -> [f64; 2] {
        let t = self.thickness_units();
        match self.sides {
            Sides::One => [0.0, t],
            Sides::Both => [-0.5 * t, 0.5 * t],
        }
    }

    /// How far any point of a panel lies from its zero-thickness facet, in paper units: two
    /// panels are at least `d − 2·reach` apart when their facets are `d` apart.
    pub fn reach_units(&self) -> f64 {
        let [lo, hi] = self.slab_units();
        lo.abs().max(hi.abs())
    }
}

/// Default alignment-hole diameter, mm.
pub const DEFAULT_HOLE_MM: f64 = 3.0;

/// How the plies of a laminate are laid out to be cut (issue 50): the laser's kerf, the
/// tabs that hold each panel in its ply until the release cut, the alignment holes and the
/// sheet. Lengths in mm. It changes no panel: only the drawings.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Laminate {
    /// The laser's kerf, mm (finite, ≥ 0): every cut is offset by half of it so that the
    /// part keeps its nominal size.
    pub kerf: f64,
    /// Width of the tabs (bridges) left in each panel's cut on the rigid plies, mm (0: no
    /// tabs).
    pub tab_width: f64,
    /// Diameter of the alignment holes, mm (finite, > 0).
    pub hole: f64,
    /// The sheet, `[width, height]` mm; `None`: the pattern's bounds plus the margin.
    pub sheet: Option<[f64; 2]>,
}

impl Default for Laminate {
    fn default() -> Self {
        Laminate {
            kerf: 0.0,
            tab_width: 0.0,
            hole: DEFAULT_HOLE_MM,
            sheet: None,
        }
    }
}

impl Laminate {
    /// Check every value; `Err((field, what is allowed))` names the first bad one.
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let within = |field: &'static str, v: f64, lo_open: bool| {
            let ok =
                v.is_finite() && v <= MAX_LENGTH_MM && if lo_open { v > 0.0 } else { v >= 0.0 };
            if ok {
                Ok(())
            } else {
                let lo = if lo_open { "(0" } else { "[0" };
                Err((
                    field,
                    format!("must be a number of mm in {lo}, {MAX_LENGTH_MM}], got {v}"),
                ))
            }
        };
        within("kerf", self.kerf, false)?;
        within("tab_width", self.tab_width, false)?;
        within("hole", self.hole, true)?;
        if self.hole <= self.kerf {
            return Err((
                "hole",
                format!(
                    "{} mm is not wider than the kerf {} mm: allowed a diameter above the kerf",
                    self.hole, self.kerf
                ),
            ));
        }
        if let Some([w, h]) = self.sheet {
            within("sheet", w, true)?;
            within("sheet", h, true)?;
        }
        Ok(())
    }

    /// Read a sheet size `"WxH"` (mm, e.g. `"600x400"`); the message says what is allowed.
    pub fn parse_sheet(text: &str) -> Result<[f64; 2], String> {
        let bad = || {
            format!(
                "{:?} is not a sheet size: allowed \"WxH\", width and height in mm in (0, {MAX_LENGTH_MM}], e.g. \"600x400\"",
                crate::text::excerpt(text, 40)
            )
        };
        let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
        let num = |s: &str| s.trim().parse::<f64>().ok();
        match (num(w), num(h)) {
            (Some(w), Some(h))
                if w.is_finite()
                    && h.is_finite()
                    && w > 0.0
                    && h > 0.0
                    && w <= MAX_LENGTH_MM
                    && h <= MAX_LENGTH_MM =>
            {
                Ok([w, h])
            }
            _ => Err(bad()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> Fabrication {
        Fabrication {
            thickness: 2.0,
            scale: 100.0,
            method: FabMethod::Tapered,
            sides: Sides::One,
            hinge_gap: DEFAULT_HINGE_GAP_MM,
            min_width: DEFAULT_MIN_WIDTH_MM,
        }
    }

    #[test]
    fn bad_values_name_their_field() {
        assert!(spec().validate().is_ok());
        for (f, bad) in [
            ("thickness", 0.0),
            ("thickness", f64::NAN),
            ("thickness", -1.0),
            ("scale", 0.0),
            ("scale", f64::INFINITY),
        ] {
            let mut s = spec();
            match f {
                "thickness" => s.thickness = bad,
                _ => s.scale = bad,
            }
            assert_eq!(s.validate().unwrap_err().0, f);
        }
        let mut s = spec();
        s.hinge_gap = -0.1;
        assert_eq!(s.validate().unwrap_err().0, "hinge_gap");
    }

    #[test]
    fn slab_and_reach_in_paper_units() {
        let mut s = spec();
        assert_eq!(s.slab_units(), [0.0, 0.02]);
        assert_eq!(s.reach_units(), 0.02);
        s.sides = Sides::Both;
        assert_eq!(s.slab_units(), [-0.01, 0.01]);
        assert_eq!(s.reach_units(), 0.01);
        for name in Sides::NAMES {
            assert_eq!(Sides::from_name(name).unwrap().name(), name);
        }
        for name in FabMethod::NAMES {
            assert_eq!(FabMethod::from_name(name).unwrap().name(), name);
        }
    }

    #[test]
    fn laminate_values_and_sheets() {
        assert!(Laminate::default().validate().is_ok());
        let bad = Laminate {
            kerf: -0.1,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().0, "kerf");
        let bad = Laminate {
            hole: 0.0,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().0, "hole");
        assert_eq!(Laminate::parse_sheet("600x400"), Ok([600.0, 400.0]));
        assert_eq!(Laminate::parse_sheet(" 210.5 X 297 "), Ok([210.5, 297.0]));
        for bad in ["axb", "600", "0x10", "-5x10", "infx3", ""] {
            assert!(
                Laminate::parse_sheet(bad).unwrap_err().contains("WxH"),
                "{bad}"
            );
        }
    }
}
