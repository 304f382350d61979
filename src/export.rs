//! `export` module (see ARCHITECTURE.md).
