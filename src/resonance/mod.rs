//! Ground resonance of a rotor deck on its airframe (docs/stability.md): the deck's blades
//! reduced to rigid blades on their lag hinges ([`crate::stability`]), each blade's damper
//! linearised at the operating point, the airframe's in-plane directions under the hub, over a
//! range of rotor speeds. Isotropic rotors: eigenvalues of the constant-coefficient equations
//! in multi-blade (Coleman) coordinates; rotors whose blades differ: Floquet exponents of the
//! periodic equations over one revolution.
pub mod air;
pub mod amplitude;
pub mod band;
pub mod rigid_blade;

mod ground;
mod job;
mod report;
mod time;
pub mod tracking;
pub use ground::*;
pub use job::*;
pub use report::*;
pub use time::*;
