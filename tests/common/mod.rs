#![allow(dead_code)]
use rotorsim::structure::*;

pub fn uniform(
    ea: f64,
    ga: f64,
    gj: f64,
    ei2: f64,
    ei3: f64,
    m: f64,
    i1: f64,
    i2: f64,
    i3: f64,
) -> SectionTable {
    SectionTable::uniform(SectionProps {
        s_m: 0.0,
        ea,
        ei2,
        ei3,
        gj,
        ga2: ga,
        ga3: ga,
        m,
        i1,
        i2,
        i3,
        cm2: 0.0,
        cm3: 0.0,
        sc2: 0.0,
        sc3: 0.0,
        ca2: 0.0,
        ca3: 0.0,
    })
}
