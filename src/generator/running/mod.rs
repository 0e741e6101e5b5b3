//! RUNNER: the knowledge-driven running generator of Bruderlin & Calvert (1996).
pub mod attributes;
pub mod curves;
pub mod dims;
pub mod equations;
pub mod params;
pub mod phase;
pub mod state;
