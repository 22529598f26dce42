//! Designs found by the search, as the variables tests rebuild them from.

/// The flasher cuboid's design of graph "1, 9", modes up, up (flat area 54.8), from
/// `foldsynth synthesize grammar/flasher_cuboid.toml --n-max 2`: rigid over its motion.
pub const FLASHER_1_9: [(&str, f64); 12] = [
    ("l_1,9", 2.0),
    ("l_1,10", 2.0),
    ("l_1,11", 0.1),
    ("l_9,21", 2.0),
    ("l_9,22", 2.0),
    ("l_9,23", 2.0),
    ("α_9", 1.5757459817734865),
    ("α_10", 1.4621383502335963),
    ("α_11", 0.1745329251994492),
    ("α_21", 2.0177084022658),
    ("α_22", 1.1011805368487178),
    ("α_23", 2.040536276595077),
];
