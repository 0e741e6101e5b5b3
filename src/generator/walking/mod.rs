//! KLAW: goal-directed, dynamic walking (Bruderlin & Calvert 1989).
pub mod body;
pub mod dynamics;
pub mod integrate;
pub mod lagrange;
