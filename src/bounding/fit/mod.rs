//! Fitting helpers (placeholder).
