//! Every WGSL file in `shaders/` is parsed and validated by naga as part of
//! each pass module it belongs to, in every variant of the pass's `override`
//! constants; all failures are reported at once. Also checks the Rust uniform
//! structs against the WGSL layout naga computes.

use cumulus::config::RenderMethod;
use cumulus::gpu::shaders::{FILES, Pass};
use cumulus::gpu::uniform::FrameUniform;
use cumulus::methods::raymarch::pack::{GpuParcel, GridUniform, ParcelsUniform};

fn parse(src: &str) -> Result<(naga::Module, naga::valid::ModuleInfo), String> {
    let module = naga::front::wgsl::parse_str(src).map_err(|e| e.emit_to_string(src))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .map_err(|e| e.emit_to_string(src))?;
    Ok((module, info))
}

/// All 2^n combinations of the pass's boolean overrides under `method`.
fn variants(pass: Pass, method: RenderMethod) -> Vec<naga::back::PipelineConstants> {
    let names = pass.overrides(method);
    (0..1u32 << names.len())
        .map(|bits| {
            names
                .iter()
                .enumerate()
                .map(|(i, n)| (n.to_string(), ((bits >> i) & 1) as f64))
                .collect()
        })
        .collect()
}

#[test]
fn every_pass_module_validates_in_every_variant() {
    let mut failures = Vec::new();
    let mut checked = 0;
    for (pass, method) in Pass::ALL
        .into_iter()
        .flat_map(|p| RenderMethod::ALL.map(|m| (p, m)))
        .filter(|(p, m)| p.used_by(*m))
    {
        let src = pass.source(method);
        let (module, info) = match parse(&src) {
            Ok(m) => m,
            Err(e) => {
                failures.push(format!("{} ({method}): {e}", pass.name()));
                continue;
            }
        };
        for constants in variants(pass, method) {
            for ep in &module.entry_points {
                let r = naga::back::pipeline_constants::process_overrides(
                    &module,
                    &info,
                    Some((ep.stage, ep.name.as_str())),
                    &constants,
                );
                if let Err(e) = r {
                    failures.push(format!(
                        "{} ({method}) {} {constants:?}: {e}",
                        pass.name(),
                        ep.name
                    ));
                }
                checked += 1;
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    // Per method, variants × entry points (vertex + fragment, or the
    // bake's splat + resolve): exact 2·(4 + 2 + 4 + 16), baked
    // 2·(2 + 2 + 2 + 4 + 8): every pass of both methods was checked.
    assert!(
        checked >= 2 * (4 + 2 + 4 + 16) + 2 * (2 + 2 + 2 + 4 + 8),
        "checked {checked}"
    );
}

#[test]
fn every_file_in_shaders_dir_is_assembled() {
    fn wgsl_files(dir: &std::path::Path, prefix: &str, out: &mut Vec<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let entry = entry.unwrap();
            let name = format!("{prefix}{}", entry.file_name().to_string_lossy());
            if entry.path().is_dir() {
                wgsl_files(&entry.path(), &format!("{name}/"), out);
            } else if name.ends_with(".wgsl") {
                out.push(name);
            }
        }
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut on_disk = Vec::new();
    wgsl_files(&dir, "", &mut on_disk);
    let missing: Vec<_> = on_disk
        .iter()
        .filter(|name| !FILES.iter().any(|(n, _)| n == name))
        .collect();
    assert!(missing.is_empty(), "not used by any pass: {missing:?}");
    for (name, _) in FILES {
        let used = Pass::ALL.iter().any(|p| {
            RenderMethod::ALL.iter().any(|m| {
                p.assembly(*m)
                    .is_ok_and(|a| a.files.iter().any(|f| f == name))
            })
        });
        assert!(used, "{name} is in no pass module");
    }
}

/// Size of a named struct as naga lays it out.
fn wgsl_struct_size(module: &naga::Module, name: &str) -> u32 {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, _) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    layouter[handle].size
}

#[test]
fn rust_uniforms_match_wgsl_layout() {
    let src = Pass::Clouds.source(RenderMethod::Exact);
    let (module, _) = parse(&src).unwrap();
    assert_eq!(
        wgsl_struct_size(&module, "Frame") as usize,
        std::mem::size_of::<FrameUniform>()
    );
    assert_eq!(
        wgsl_struct_size(&module, "Parcel") as usize,
        std::mem::size_of::<GpuParcel>()
    );
    assert_eq!(
        wgsl_struct_size(&module, "Parcels") as usize,
        std::mem::size_of::<ParcelsUniform>()
    );
    assert_eq!(
        wgsl_struct_size(&module, "Grid") as usize,
        std::mem::size_of::<GridUniform>()
    );
    // The temporal uniform, declared by the march and the resolve alike.
    let temporal = std::mem::size_of::<cumulus::methods::raymarch::temporal::TemporalUniform>();
    assert_eq!(wgsl_struct_size(&module, "Temporal") as usize, temporal);
    let (resolve, _) = parse(&Pass::Temporal.source(RenderMethod::Baked)).unwrap();
    assert_eq!(wgsl_struct_size(&resolve, "Temporal") as usize, temporal);
    // 16-byte fields only: no vec3 padding surprises.
    assert_eq!(std::mem::size_of::<FrameUniform>() % 16, 0);
    assert_eq!(std::mem::size_of::<GpuParcel>() % 16, 0);
}
