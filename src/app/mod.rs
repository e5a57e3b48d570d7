//! The live window (winit + egui): watch clouds form, edit the profile.
