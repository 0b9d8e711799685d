//! Reports: plots, HTML, MCAP out.
pub mod plot;
