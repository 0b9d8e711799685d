//! rotorsim: rotor-blade aeroelastic loads with physics-based hydraulic devices.
//!
//! Reference: O. A. Bauchau and H. Liu, "On the Modeling of Hydraulic Components in Rotorcraft
//! Systems" (equation numbers in doc comments, "Eq. N", refer to that paper).
pub mod aero;
pub mod analysis;
pub mod cli;
pub mod diagnose;
pub mod flight;
pub mod hydraulics;
pub mod io;
pub mod loads;
pub mod overrides;
pub mod periodic;
pub mod report;
pub mod rotor;
pub mod run;
pub mod sensitivity;
pub mod solver;
pub mod stability;
pub mod structural;
pub mod structure;
pub mod sweep;
