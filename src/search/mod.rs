//! Enumeration of design alternatives: graphs × rigid body modes × gripping candidates.
