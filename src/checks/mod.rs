//! Checks and single analyses, each a command: the damper on its virtual test bench (`rotorsim
//! bench`), a blade's or model deck's modes and fan plot (`rotorsim modes`), a hinged blade's lag
//! decay (`rotorsim decay`), and a model deck's (docs/model_deck.md) static solution
//! (`rotorsim static`, [`static_job`]), time march (`rotorsim dynamic`) and the structural
//! solver's verification suite (`rotorsim verify`). Each is an options type read by the command
//! line and a job that writes the result folder and returns what the command prints.
pub mod bench;
pub mod decay;
pub mod dynamic;
pub mod modes;
pub mod static_job;
pub mod verify;
