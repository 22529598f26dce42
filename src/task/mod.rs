//! Design task files (`grammar/*.toml`): parsing and validation.
