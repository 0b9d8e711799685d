//! Model deck (TOML).
