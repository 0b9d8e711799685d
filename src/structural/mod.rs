//! Analyses of a model deck (docs/model_deck.md) as library calls: `rotorsim static`
//! ([`static_job`]), `rotorsim dynamic` ([`dynamic`]) and the verification suite of the
//! structural solver, `rotorsim verify` ([`verify`]). Each is an options type read by the command
//! line and a job that writes the result folder and returns what the command prints.
pub mod dynamic;
pub mod static_job;
pub mod verify;
