//! Files people open: FOLD, SVG, OBJ/STL, pictures, animations, plots, report.
