//! `scene` module (see ARCHITECTURE.md).
