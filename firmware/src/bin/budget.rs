//! Cycle and stack bench of the model steps and the control step, for `hil-sim budget`.
//!
//! Built with the shipping flags (release profile: fat LTO, opt-level 3, codegen-units 1;
//! `thumbv7em-none-eabihf`), linked for QEMU's `mps2-an386` (Cortex-M4 with FPU, memory in
//! `budget-link.x`) and run there with semihosting. For every model in the registry and
//! for the control step it
//!
//! 1. prints `step <name> <address> <calls>` (semihosting, stdout): the address of the
//!    function that is measured and how many times it is called;
//! 2. calls that function through a function pointer laundered by
//!    [`core::hint::black_box`], so LTO can neither inline it into the loop nor specialise
//!    it for the inputs, once per sample of an input sweep of the 20 kHz operating envelope
//!    that visits every branch that matters there (rest, travel, reversals, zero crossings
//!    of the hysteretic state, sign changes of the input; for the control step:
//!    calibration, running with a multi-sine reference, reference limiting, the
//!    demagnetising pulse, disable/enable, a Hall rail fault with its trip, reset and
//!    recalibration; the slow supervisor pass `supervisor_slow` every 20th sample, as the
//!    firmware runs it at 1 kHz);
//! 3. prints `outside <name> <address> <calls>` and runs a second sweep beyond the
//!    envelope (500 Hz full-span sine, jumps of the whole span in one sample), which
//!    `hil-sim budget` reports apart, without a budget.
//!
//! `hil-sim budget` traces the run (`-singlestep -d exec,cpu,nochain`) and counts, per
//! call, the instructions from the function's entry to its return and the lowest stack
//! pointer in between. The same binary runs on a real board (the bench only needs a
//! semihosting debugger); nothing here depends on QEMU.
//!
//! Parameter sets: the published ones where the papers give them (seed 000 Tables 3–6 for
//! the clutch models, Spencer's 1997 set), otherwise valid sets of the size the registry
//! declares (the cost of the operator and network models depends on their size, not on
//! the values).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod bench {
    use core::hint::black_box;

    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprintln};
    use model_core::control::ValidatedConfig;
    use model_core::control::{ControlConfig, ControlInput, ControlOutput, ControlState, ControlStep, LoopMode};
    use model_core::models::{
        algebraic, arctan, arctan_inertia, bingham, bouc_wen, bouc_wen_asym, dahl, gpi, hammerstein_wiener, lugre,
        maxwell_slip, narx, prandtl_ishlinskii, preisach, spencer, tanh, trig,
    };
    use model_core::rate::RateParams;
    use model_core::{Kin, Model};

    /// The firmware's control period (20 kHz).
    const DT: f32 = 1.0 / 20_000.0;

    /// The input sweep of one model: input `off ± amp`, command `u_off ± u_amp`.
    #[derive(Clone, Copy)]
    struct Sweep {
        amp: f32,
        off: f32,
        u_off: f32,
        u_amp: f32,
    }

    /// The operating envelope at 20 kHz: rest, 200 samples of a full-span 25 Hz sine (the
    /// papers' excitations reach 10 Hz) through its peak (the reversal, then the zero
    /// crossing of the hysteretic state that follows), then a 2 % dither at 200 Hz
    /// (reversals every 50 samples). Segments continue from where the previous one ended.
    const ENVELOPE: [Segment; 3] = [
        Segment { n: 6, per: 0.0, gain: 0.0, phase: 0.0 },
        Segment { n: 200, per: 800.0, gain: 1.0, phase: 1.45 },
        Segment { n: 40, per: 100.0, gain: 0.02, phase: 0.0 },
    ];
    /// Outside it (reported apart, without a budget): a 500 Hz full-span sine (large
    /// steps, a reversal inside most of them) and jumps of the whole span in one sample.
    const OUTSIDE: [Segment; 1] = [Segment { n: 45, per: 40.0, gain: 1.0, phase: 0.0 }];
    const JUMPS: [f32; 6] = [1.0, -1.0, 1.0, 0.5, -2.0, 2.0];

    #[derive(Clone, Copy)]
    struct Segment {
        n: u32,
        /// Samples per period (0: rest).
        per: f32,
        /// Amplitude as a fraction of the sweep's.
        gain: f32,
        /// Start phase, rad.
        phase: f32,
    }

    const fn calls(segs: &[Segment], jumps: usize) -> u32 {
        let mut n = jumps as u32;
        let mut i = 0;
        while i < segs.len() {
            n += segs[i].n;
            i += 1;
        }
        n
    }

    /// The input where the sweep starts: the first sine segment's start.
    fn start(sw: Sweep, segs: &[Segment]) -> f32 {
        sw.off + segs.iter().find(|s| s.per > 0.0).map_or(0.0, |s| sw.amp * s.gain * micromath::F32Ext::sin(s.phase))
    }

    /// Visit every sample of the segments with exact kinematics (x, ẋ, ẍ of a sine that
    /// continues from the previous segment's last input), then the jumps (with the rate a
    /// backward difference gives).
    fn for_each_sample(sw: Sweep, segs: &[Segment], jumps: &[f32], mut f: impl FnMut(Kin)) {
        use micromath::F32Ext;
        let mut x = start(sw, segs);
        for seg in segs {
            let w = if seg.per > 0.0 { 2.0 * core::f32::consts::PI / seg.per } else { 0.0 };
            let (c, s) = (w.cos(), w.sin());
            let omega = w / DT;
            let (mut sn, mut cs) = (seg.phase.sin(), seg.phase.cos());
            let amp = sw.amp * seg.gain;
            let base = x - amp * sn;
            for _ in 0..seg.n {
                (sn, cs) = (sn * c + cs * s, cs * c - sn * s);
                x = base + amp * sn;
                let u = sw.u_off + sw.u_amp * (0.5 + 0.5 * cs);
                f(Kin::new(x, amp * omega * cs, -amp * omega * omega * sn, u));
            }
        }
        for j in jumps {
            let next = sw.off + j * sw.amp;
            f(Kin::new(next, (next - x) / DT, 0.0, sw.u_off + sw.u_amp));
            x = next;
        }
    }

    fn fail(what: &str) -> ! {
        hprintln!("error {}", what);
        debug::exit(debug::EXIT_FAILURE);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    /// Measure `M::step` over the envelope, then (as `outside`) beyond it.
    fn model<M: Model>(flat: &[f32], sw: Sweep) {
        let m = match M::from_params(flat, DT) {
            Ok(m) => m,
            Err(e) => {
                hprintln!("error {}: {}", M::ID, e);
                fail(M::ID)
            }
        };
        let step: fn(&M, &mut M::State, &Kin) -> f32 = black_box(<M as Model>::step);
        for (kind, segs, jumps) in [("step", &ENVELOPE[..], &[][..]), ("outside", &OUTSIDE[..], &JUMPS[..])] {
            hprintln!("{} {} {:#x} {}", kind, M::ID, step as usize, calls(segs, jumps.len()));
            let mut s = m.initial_state(&Kin::new(start(sw, segs), 0.0, 0.0, sw.u_off));
            for_each_sample(sw, segs, jumps, |k| {
                black_box(step(black_box(&m), &mut s, black_box(&k)));
            });
        }
    }

    /// A model that maps the field to torque: its step, then the firmware's control step
    /// with it (`control_step_<id>`).
    fn clutch<M: Model>(flat: &[f32], sw: Sweep) {
        model::<M>(flat, sw);
        control_of::<M>(flat);
    }

    const fn sw(amp: f32, off: f32) -> Sweep {
        Sweep { amp, off, u_off: 0.0, u_amp: 0.0 }
    }
    const fn swu(amp: f32, off: f32, u_off: f32, u_amp: f32) -> Sweep {
        Sweep { amp, off, u_off, u_amp }
    }

    /// Fill `out` with a deterministic pattern in `[-a, a]`.
    fn pattern(out: &mut [f32], a: f32) {
        let mut v = 0.37f32;
        for o in out.iter_mut() {
            v = v * 3.7 - micromath::F32Ext::floor(v * 3.7);
            *o = a * (2.0 * v - 1.0);
        }
    }

    fn models() {
        // Seed 000 (clutch, B in mT as fitted there): Table 6, 3 (Wen's naming), 4, 5 averages.
        clutch::<algebraic::Registered>(&[4.606, -0.076, 0.033, 0.797], sw(1.5, 0.0));
        clutch::<bouc_wen::Registered>(&[2.162, 0.400, 1.0, -1.486, 1.0, -0.077, 5.861, 0.0], sw(1.5, 0.0));
        clutch::<lugre::Registered>(&[4.312, 5.771, 0.003, -0.151, 4.297, 5.225], sw(1.5, 0.0));
        clutch::<tanh::Registered>(&[0.495, 1.969, 1.603, -0.120, 4.790, 0.587], sw(1.5, 0.0));

        // Hammerstein–Wiener: nets from a pattern, poles at 0.5 (stable), range ±10.
        const HW: usize = hammerstein_wiener::Registered::N_PARAMS;
        let mut p = [0.0f32; HW];
        pattern(&mut p, 2.0);
        let f = 3 * 14 + 2 + 3;
        p[f..f + 5].copy_from_slice(&[-2.5, 2.5, -1.25, 0.3125, -0.03125]);
        p[f + 5 + 3 * 13 + 2] = -10.0;
        p[f + 5 + 3 * 13 + 3] = 10.0;
        clutch::<hammerstein_wiener::Registered>(&p, sw(1.5, 0.0));

        // The board's NARX (8 units, 86 values; `BUDGETS` row `narx`).
        const NX: usize = narx::Registered::N_PARAMS;
        let mut p = [0.0f32; NX];
        pattern(&mut p, 1.0);
        p[..4].copy_from_slice(&[0.0, 1.0, 0.0, 1.0]);
        p[NX - 2] = -50.0;
        p[NX - 1] = 50.0;
        clutch::<narx::Registered>(&p, sw(1.5, 0.0));

        // Dampers (x in cm, command in A or V).
        model::<bingham::Registered>(&[50.0, 10.0, 5.0, 1.0, 10.0, 0.5, 0.2, 0.1, 0.05, 1.0], swu(1.0, 0.0, 0.0, 2.0));
        model::<spencer::Registered>(
            &[21.0, 3.5, 46.9, 283.0, 2.95, 5.0, 14.3, 140.0, 695.0, 363.0, 363.0, 301.0, 2.0, 190.0],
            swu(1.0, 0.0, 0.0, 2.0),
        );
        clutch::<dahl::Registered>(&[50.0, 20.0, 300.0, 200.0, 5.0, 10.0, 2.0, 30.0], swu(1.0, 0.0, 0.0, 2.0));
        let at = [10.0, 5.0, 400.0, 20.0, 300.0, 50.0, 30.0, 1.0, 0.5, 0.01];
        model::<arctan::Registered>(&at, swu(1.0, 0.0, 0.0, 2.0));
        let mut ai = [0.0f32; 11];
        ai[..10].copy_from_slice(&at);
        ai[10] = 0.5;
        model::<arctan_inertia::Registered>(&ai, swu(1.0, 0.0, 0.0, 2.0));
        // Seed 002 (Pacejka): quadratics with the sign structure over 0–2 A.
        model::<trig::Registered>(
            &[
                1.0, 0.5, 0.1, 0.5, 0.1, 0.05, 0.05, 0.02, 0.01, 1.0, 0.5, 0.2, 0.1, 0.1, 0.0, 1.0, 0.5, 0.1, 0.0005,
                0.0002, 0.0001,
            ],
            swu(1.0, 0.0, 0.0, 2.0),
        );

        // Seed 004 (operator models), input in [−1, 1].
        clutch::<preisach::Registered>(&[1.0, 2.0, 0.1, 0.05, 0.1, 1.0, -1.0, 1.0, 0.0], sw(0.9, 0.0));
        let mut p = [0.0f32; 22];
        p[0] = 1.0;
        p[1] = 0.05;
        for i in 0..10 {
            p[2 + i] = 0.1 * i as f32;
            p[12 + i] = 0.5 / (1.0 + i as f32);
        }
        clutch::<prandtl_ishlinskii::Registered>(&p, sw(0.9, 0.0));
        clutch::<gpi::Registered>(&[1.0, 0.1, 1.0, 1.0, 1.0, 0.5, 0.2, 1.0, 0.5, 0.2, -1.0, 1.0, 0.0], sw(0.9, 0.0));
        let mut p = [0.0f32; 22];
        p[0] = 0.1;
        for i in 0..10 {
            p[1 + i] = 1.0 + i as f32;
            p[11 + i] = 0.1 * (1.0 + i as f32);
        }
        p[21] = 0.2;
        clutch::<maxwell_slip::Registered>(&p, sw(0.9, 0.0));
        clutch::<bouc_wen_asym::Registered>(
            &[0.5, 1.0, 1.0, 1.0, 0.5, 0.5, 1.0, 0.0, 0.5, 0.5, 0.5, 1.0],
            sw(0.9, 0.0),
        );
    }

    type StepOf<M> =
        fn(&ControlStep<M>, &ValidatedConfig, &mut ControlState<<M as Model>::State>, ControlInput) -> ControlOutput;
    type SlowOf<M> = fn(&ControlStep<M>, &ValidatedConfig, &mut ControlState<<M as Model>::State>, f32);

    /// The control step of model `M` (as `firmware::runner::Loop` runs it) over the same
    /// sequence as [`control_step`], reported as `control_step_<id>` (and its slow pass as
    /// `supervisor_slow_<id>`: it steps the model too, for the feed-forward's linearisation).
    fn control_of<M: Model>(flat: &[f32]) {
        let Ok(model) = M::from_params(flat, DT) else { fail(M::ID) };
        let Ok(rate) = RateParams::filtered(DT, 150.0) else { fail("rate") };
        let Ok(step) = ControlStep::new(model, rate) else { fail("control step") };
        let f: StepOf<M> = black_box(ControlStep::<M>::step);
        let slow: SlowOf<M> = black_box(ControlStep::<M>::slow);
        hprintln!("step control_step_{} {:#x} {}", M::ID, f as usize, N);
        hprintln!("step supervisor_slow_{} {:#x} {}", M::ID, slow as usize, N.div_ceil(SLOW));
        let cfg = control_config();
        let mut s = step.state();
        drive_sequence(|k, input| {
            if k % SLOW == 0 {
                slow(black_box(&step), black_box(&cfg), &mut s, black_box(40.0));
            }
            black_box(f(black_box(&step), black_box(&cfg), &mut s, black_box(input)))
        });
    }

    const N: u32 = 440;
    /// The slow pass runs before every `SLOW`-th sample (1 kHz at 20 kHz).
    const SLOW: u32 = 20;

    fn control_config() -> ValidatedConfig {
        let cfg = ControlConfig {
            mode: LoopMode::Torque,
            calib_samples: 8.0,
            demag_samples: 6.0,
            temp_coeff: 0.002,
            b_band: 0.3,
            ff_lead_s: 0.002,
            ..ControlConfig::defaults(DT)
        };
        let Ok(cfg) = cfg.validate() else { fail("control config") };
        cfg
    }

    /// The control step's input sequence against a crude RL coil with B ∝ i: `f(k, input)`
    /// runs sample `k` and returns the step's output.
    fn drive_sequence(mut f: impl FnMut(u32, ControlInput) -> ControlOutput) {
        let c = *control_config().get();
        let (r_coil, l_coil, supply) = (4.0f32, 0.02f32, 24.0f32);
        let mut i = 0.0f32;
        for k in 0..N {
            let t = k as f32 * DT;
            // Reference: 0 while calibrating, a fast multi-sine 2–14 N·m (beyond the 15 N·m
            // limit at its peaks), back to 0 (demagnetising pulse), disabled, enabled; then
            // the Hall output at its upper rail (trips on the third sample), reset, and a
            // recalibration once the next slow pass has run.
            let reference = match k {
                0..=20 => 0.0,
                21..=300 => {
                    let w = 2.0 * core::f32::consts::PI * t;
                    8.0 + 4.0 * micromath::F32Ext::sin(300.0 * w) + 4.0 * micromath::F32Ext::sin(730.0 * w)
                }
                301..=330 => 0.0,
                _ => 6.0,
            };
            let b = 0.2 * i;
            let noise = (k % 3) as f32;
            let hall = if (380..386).contains(&k) { 4095 } else { (c.hall_offset + b / c.hall_gain + noise) as u16 };
            let current = (c.current_offset + i / c.current_gain + noise) as u16;
            let input = ControlInput {
                enable: !(340..350).contains(&k),
                reset: k == 390,
                ..ControlInput::new(hall, current, supply, if k == 200 { 30.0 } else { reference })
            };
            let o = f(k, input);
            let v = if o.pwm_enable { o.duty * supply } else { 0.0 };
            i += DT * (v - r_coil * i) / l_coil;
        }
    }

    type Step = ControlStep<algebraic::Algebraic>;
    type StepFn = fn(&Step, &ValidatedConfig, &mut ControlState<()>, ControlInput) -> ControlOutput;
    type SlowFn = fn(&Step, &ValidatedConfig, &mut ControlState<()>, f32);

    /// The firmware's control step with its compiled-in default model (the algebraic model
    /// in T, as `hil-sim loop` identifies it) against a crude RL coil with B ∝ i.
    fn control_step() {
        let Ok(model) = algebraic::Algebraic::new(20.0, -0.05, -10.0, 0.8, DT) else { fail("control model") };
        let Ok(rate) = RateParams::filtered(DT, 150.0) else { fail("rate") };
        let Ok(step) = ControlStep::new(model, rate) else { fail("control step") };
        let cfg = control_config();
        let f: StepFn = black_box(Step::step);
        let slow: SlowFn = black_box(Step::slow);
        hprintln!("step control_step {:#x} {}", f as usize, N);
        hprintln!("step supervisor_slow {:#x} {}", slow as usize, N.div_ceil(SLOW));
        let mut s = step.state();
        drive_sequence(|k, input| {
            if k % SLOW == 0 {
                slow(black_box(&step), black_box(&cfg), &mut s, black_box(40.0));
            }
            black_box(f(black_box(&step), black_box(&cfg), &mut s, black_box(input)))
        });
    }

    #[entry]
    fn main() -> ! {
        models();
        control_step();
        hprintln!("done");
        debug::exit(debug::EXIT_SUCCESS);
        #[allow(clippy::empty_loop)]
        loop {}
    }

    /// The device interrupt vectors cortex-m-rt expects (its `device` feature is on for the
    /// whole package because embassy-stm32 enables it). The bench uses no interrupt; the one
    /// entry ends the run as a failure should anything fire.
    #[link_section = ".vector_table.interrupts"]
    #[no_mangle]
    #[used]
    static __INTERRUPTS: [unsafe extern "C" fn(); 1] = [unexpected_interrupt];

    unsafe extern "C" fn unexpected_interrupt() {
        fail("interrupt")
    }

    #[panic_handler]
    fn panic(_: &core::panic::PanicInfo) -> ! {
        fail("panic")
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    println!(
        "budget: the cycle/stack bench for QEMU's mps2-an386; build it with \
         `cargo build --release -p firmware --target thumbv7em-none-eabihf --bin budget` \
         and run it with `hil-sim budget`"
    );
}
