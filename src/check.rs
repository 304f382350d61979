//! `check` module (see ARCHITECTURE.md).
