//! Mesh input, validation, topology and vertex normals.
