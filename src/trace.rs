//! `trace` module (see ARCHITECTURE.md).
