//! PNG charts with plotters (parcel diagram, bench plots). Fonts come from
//! `epaint_default_fonts`, so no system font library is needed.
