//! Per-trial plot (placeholder until written).
