//! Flight records (CSV triple and MCAP), unit conversion at the edges, airload replay.
