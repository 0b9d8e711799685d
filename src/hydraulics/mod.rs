//! Hydraulic elements on pressure states (chamber, orifice, relief valve, check valve), composed
//! into devices (actuator, dampers, dashpots), with sub-stepping integrators. Paper Eqs. (1)-(8).
