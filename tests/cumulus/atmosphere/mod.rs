//! The atmosphere: soundings, the `[atmosphere]` table, pressure, wind,
//! parcel theory against MetPy, CAPE/CIN, and `cumulus parcel`.

mod cape;
mod lifting;
mod metpy;
mod parcel_cli;
mod pressure;
mod profiles;
mod sounding;
mod spec;
mod wind;
