//! The optimization model of one crease pattern graph for a design task (thesis Sec. 5.2, 5.4).
