//! The embassy application (bare-metal target only).
//!
//! Skeleton: clocks, defmt logging and the model-core wiring. The ADC sampling of the
//! flux sensor, the coil PWM and the control loop come with the firmware issue; until
//! then the estimator is ticked at a low rate with a synthetic input just to prove that
//! model-core links and runs on the Cortex-M4F.

use defmt::{info, warn};
use embassy_executor::Spawner;
use embassy_stm32::Config;
use embassy_time::{Duration, Ticker};
use micromath::F32Ext;
use model_core::models::algebraic::Algebraic;
use model_core::rate::RateParams;
use model_core::{Estimator, Sample};
use {defmt_rtt as _, panic_probe as _};

/// Control/sample rate the estimator is built for (the real loop will run at 20 kHz).
const SAMPLE_HZ: f32 = 20_000.0;
const DT: f32 = 1.0 / SAMPLE_HZ;

/// Algebraic model (seed 000 eq. 14), seed 000 Table 6 average parameters.
const K: f32 = 4.606;
const C: f32 = -0.076;
const ALPHA: f32 = 0.033;
const T0: f32 = 0.797;

/// Clock tree: 16 MHz HSI / 4 × 85 = 340 MHz VCO, / 2 on PLL R = 170 MHz SYSCLK, with
/// range-1 boost mode (required above 150 MHz). AHB/APB1/APB2 undivided (170 MHz).
/// For a board crystal, set `rcc.hse` and `PllSource::HSE` with a prediv giving the same
/// 4 MHz PLL input (e.g. 24 MHz HSE / 6).
fn clocks() -> Config {
    use embassy_stm32::rcc::{Pll, PllMul, PllPreDiv, PllRDiv, PllSource, Sysclk};
    let mut config = Config::default();
    config.rcc.hsi = true;
    config.rcc.pll = Some(Pll {
        source: PllSource::HSI,
        prediv: PllPreDiv::DIV4,
        mul: PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(PllRDiv::DIV2),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.boost = true;
    config
}

#[embassy_executor::main]
async fn main(_spawner: Spawner) {
    let _p = embassy_stm32::init(clocks());
    info!("MR clutch controller firmware skeleton, SYSCLK 170 MHz");

    let estimator = match Algebraic::new(K, C, ALPHA, T0, DT)
        .and_then(|m| Ok((m, RateParams::backward(DT)?)))
        .and_then(|(m, r)| Estimator::new(m, r))
    {
        Ok(e) => e,
        Err(e) => defmt::panic!("model parameters rejected: {}", defmt::Display2Format(&e)),
    };
    let mut state = estimator.state();
    info!("algebraic estimator ready: dt = {} s", DT);

    // Placeholder loop: TODO(firmware issue) replace with ADC-triggered sampling at
    // SAMPLE_HZ, the torque controller and the coil PWM. Here one synthetic 20 kHz sample
    // (a 5 Hz sine in the fitted unit of B) is processed every 100 ms of wall time.
    const F_TEST_HZ: f32 = 5.0;
    const AMPLITUDE: f32 = 0.5;
    let dphase = 2.0 * core::f32::consts::PI * F_TEST_HZ * DT;
    let mut phase = 0.0f32;
    let mut n: u32 = 0;
    let mut ticker = Ticker::every(Duration::from_millis(100));
    loop {
        let x = AMPLITUDE * phase.sin();
        let out = estimator.step(&mut state, Sample::new(x));
        if !out.flags.ok() {
            warn!("sample {}: estimator flags {=u8:#x}", n, out.flags.0);
        }
        if n.is_multiple_of(10) {
            info!("sample {}: B = {} -> T = {} N·m", n, x, out.y);
        }
        phase += dphase;
        if phase >= 2.0 * core::f32::consts::PI {
            phase -= 2.0 * core::f32::consts::PI;
        }
        n = n.wrapping_add(1);
        ticker.next().await;
    }
}
