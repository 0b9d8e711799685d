//! Aerodynamics of the blade: aerofoil tables (C81), inflow models and the blade-element
//! lifting line that turns the blade's motion into airloads (docs/aerodynamics.md).
pub mod airfoil;
pub mod c81;
pub mod inflow;
pub mod lifting_line;
pub mod section;
