//! KLAW: goal-directed, dynamic walking (Bruderlin & Calvert 1989).
pub mod attributes;
pub mod body;
pub mod collision;
pub mod dynamics;
pub mod foot;
pub mod generate;
pub mod high_level;
pub mod integrate;
pub mod lagrange;
pub mod shooting;
pub mod stance;
pub mod swing;
pub mod track;
pub mod virtual_leg;
