//! Recursive least squares (placeholder module being written).
