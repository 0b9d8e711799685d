//! Reports: plots, HTML, MCAP out.
pub mod html;
pub mod plot;
