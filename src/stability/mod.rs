//! Ground- and air-resonance stability: the mathematical core (no decks, no CLI).
//!
//! [`lag_rotor`] holds the reduced model of Coleman & Feingold (NACA TR-1351): rigid blades on
//! lag hinges on a hub that moves in the plane with the airframe. It gives the
//! constant-coefficient eigenvalues in multi-blade coordinates for an isotropic rotor
//! ([`LagRotor::coleman_eigenvalues`]) and the Floquet characteristic exponents of the
//! time-periodic equations in individual blade coordinates for any rotor
//! ([`LagRotor::floquet`]), e.g. one lag damper inoperative (Hammond, JAHS 19(4), 1974).
//! [`dampers`] integrates the same rotor with each damper as a device (its nonlinearity
//! live), for the amplitude at which the linear analysis stops being true. [`air_rotor`]
//! adds flap, quasi-steady aerodynamics in hover and the airframe's roll and pitch (air
//! resonance).
pub mod air_rotor;
pub mod dampers;
mod labels;
pub mod lag_rotor;

pub use air_rotor::{AirBlade, AirRotor, BodyAxis, BodyDof, Hover, Strip};
pub use dampers::{free_response_with_dampers, BladeDamper, DeviceResponse};
pub use lag_rotor::{
    cyclic_amplitude, AirframeAxis, LagBlade, LagRotor, Mode, ModeLabel, StabilityError,
    TimeResponse,
};
