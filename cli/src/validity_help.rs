//! The validity range of each command, printed at the end of its `--help`
//! (the checks are `trackbelt_host::validity` for the bench tests and
//! `trackbelt_host::rig` for the rig; the README's "Validity" table says
//! the same).

/// The checks of every bench run (static and dynamic test).
macro_rules! bench_checks {
    () => {
        "Every run is checked before a figure is printed (an error names the check and the value; \
a warning goes to stderr and into the JSON's \"warnings\" array):\n  \
- static equilibrium after each settle: largest generalised force ≤ 1e-4 of the weight (error)\n  \
- energy balance of the dynamic test: mechanical energy + joint damping work never above its \
start value by more than 1 % of the energy the drop releases; damping work ≥ 0 (error)\n  \
- constraint drift: loop closure ≤ 1 µm (error); its velocity ≤ 0.05 of the fastest joint (warning)\n  \
- settled: A's swing over the last period ≤ 0.3 of the drop (warning)\n  \
- time resolution: ≥ 50 time steps per period of A (warning)\n  \
- step rejections ≤ 0.1 per accepted step (warning)\n  \
- Newton failing at the smallest step, an exhausted step budget (error)"
    };
}

/// `simulate`.
pub const SIMULATE: &str = concat!(
    "Validity range: E38/E56/E76 (or a params file's law), pin or bushing joints, --step-ms up to \
about 20 (50 ms resolves a period in ~31 steps: flagged), a dynamic test long enough to ring \
down (≥ 2.5–3 s; the default 5 s), a floor stiffness of 1e3–1e8 N/m (1e9: the static settle fails, an error).\n\n",
    bench_checks!()
);

/// `paper`.
pub const PAPER: &str = concat!(
    "Validity range: the paper's nine cases at the default settings (2 ms, 5 s), all inside \
every check with no warning; the rig rows as `rig` (E56, 5 rad/s).\n\n",
    bench_checks!()
);

/// `bench`.
pub const BENCH: &str = concat!(
    "Validity range: the paper's method I test (2 ms, 5 s). The timed runs are not slowed by the \
checks: one more, untimed, run per variant goes through them.\n\n",
    bench_checks!()
);

/// `calibrate`.
pub const CALIBRATE: &str = concat!(
    "Validity range: method III tables for E38/E56/E76 fitted to static and dynamic figures; the \
calibrated model is simulated once more through the checks (its warnings in the JSON's \
\"warnings\"; a failed check is an error and nothing is written). A trial point of the fit that \
fails a check counts as a failed simulation.\n\n",
    bench_checks!()
);

/// `diagnose`.
pub const DIAGNOSE: &str = "Validity range: dynamic series at the default settings (2 ms) and \
scroll series whose drive speed stays inside the rig's range (a link passes the drive in ≥ 5 \
time steps: ±41.3 / 28.2 / 20.9 rad/s for E38 / E56 / E76). Every forward run of a dynamic \
series passes the bench checks (static equilibrium, energy balance, loop closure: a trial that \
fails one counts as a failed simulation); the summary comparison runs them on its 5 s test and \
appends any warning to its evidence; a scroll profile outside the speed range is an error.";

/// `synth`.
pub const SYNTH: &str = "Validity range: dynamic series (2 ms steps) pass the bench checks \
(static equilibrium, energy balance, loop closure) before they are sampled, else nothing is \
written; scroll series must keep the drive speed inside the rig's range (±41.3 / 28.2 / 20.9 \
rad/s for E38 / E56 / E76).";

/// `rig`.
pub const RIG: &str = "Validity range: |drive speed| up to the speed at which a link passes the \
drive in 5 time steps (±41.3 / 28.2 / 20.9 rad/s for E38 / E56 / E76 on 300 mm wheels), else an \
error. Checked after the run: belt slip ≤ 5 % and bending loss ≤ drive torque (errors); a \
measured phase shorter than one link passage, halves of it differing > 10 %, or more than one \
rejected step per accepted step are warnings.";
