//! Structural elements: rotations, geometrically exact beams, rigid bodies, joints, forces.
// Index loops mirror the component formulas of the formulation.
#![allow(clippy::needless_range_loop)]
pub mod beam;
mod beam_tangent;
pub mod deck;
pub mod deck_text;
pub mod elastomer;
pub mod hydraulic;
pub mod joint;
pub mod kin;
pub mod model;
pub mod real;
pub mod rigid;
pub mod rotation;
pub mod section;

pub use beam::{Beam, BeamLoad, SectionLoad};
/// Fixture of the beam tangent tests, for the tangent cost benchmark.
#[doc(hidden)]
pub use beam_tangent::fixture as beam_tangent_fixture;
pub use hydraulic::{AppliedForce, HydraulicForceElement, HydraulicProbe};
pub use joint::{AngleLaw, BushingCoeffs, Joint, JointKind};
pub use kin::{EvalCtx, NodeKin, Seed, TimeTable};
pub use model::{
    DistributedLoad, Element, ElementError, ElementOutput, LoadPoint, Model, ModelError, Sensor,
    SensorKind, StepElement,
};
pub use rigid::{PointLoad, RigidBody};
pub use section::{SectionProps, SectionTable};
