//! Crease pattern graphs, the rules r1 and r2, enumeration and filters (thesis Sec. 5.1–5.2).
