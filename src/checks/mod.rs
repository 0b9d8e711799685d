//! Component checks, each a command: the damper on its virtual test bench (`rotorsim bench`), a
//! blade's or model deck's modes and fan plot (`rotorsim modes`), a hinged blade's lag decay
//! (`rotorsim decay`).
pub mod bench;
pub mod decay;
pub mod modes;
