//! The atmosphere: soundings, the `[atmosphere]` table, pressure, wind,
//! parcel theory against MetPy, CAPE/CIN, and `cumulus parcel`.

mod cape;
mod diagnostics;
mod indices;
mod lifting;
mod metpy;
mod parcel_cli;
mod pressure;
mod profiles;
mod reference;
mod sounding;
mod spec;
mod wind;
