//! The MR clutch simulator: one module per physical effect, integrated in f64 with a
//! fixed sub-step (`pwm_substeps` per PWM period, 3.1 µs at 20 kHz by default) so each
//! PWM switching edge of the coil voltage is resolved.
//!
//! Chain: H-bridge duty → [`coil`] current → [`magnetic`] B_core (hysteresis) → Hall
//! field and eddy-lagged fluid field → [`fluid`] torque at the [`motor`] slip speed and
//! the [`thermal`] state → [`sensors`] (Hall, current shunt, temperature, load cell).

pub mod coil;
pub mod fluid;
pub mod limits;
pub mod magnetic;
pub mod motor;
pub mod sensors;
pub mod thermal;

use serde::{Deserialize, Serialize};

use coil::{Coil, CoilFault, CoilParams, Drive};
use fluid::FluidParams;
use magnetic::{Magnetic, MagneticParams};
use motor::MotorParams;
use sensors::{HallFault, Noise, SensorParams};
use thermal::ThermalParams;

/// Everything that describes one clutch and its test bench (TOML `[clutch]` table).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClutchParams {
    pub coil: CoilParams,
    pub magnetic: MagneticParams,
    pub fluid: FluidParams,
    pub thermal: ThermalParams,
    pub motor: MotorParams,
    pub sensors: SensorParams,
    /// Ambient and initial temperature, °C.
    pub ambient_c: f64,
    pub initial_c: f64,
    /// Sub-steps per PWM period.
    pub pwm_substeps: usize,
}

impl Default for ClutchParams {
    /// The reference clutch (numbers and sources in each module).
    fn default() -> Self {
        Self {
            coil: CoilParams::default(),
            magnetic: MagneticParams::default(),
            fluid: FluidParams::default(),
            thermal: ThermalParams::default(),
            motor: MotorParams::default(),
            sensors: SensorParams::default(),
            ambient_c: 20.0,
            initial_c: 20.0,
            pwm_substeps: 16,
        }
    }
}

/// Faults injected into the plant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlantFaults {
    pub coil: CoilFault,
    pub hall: HallFault,
    /// Supply voltage override, V.
    pub supply_v: Option<f64>,
}

/// What the controller's ADCs and the bench see at one sampling instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measurement {
    pub hall: u16,
    pub current: u16,
    pub supply_v: f64,
    pub temperature: f64,
}

/// The simulated clutch.
pub struct Plant {
    pub p: ClutchParams,
    pub faults: PlantFaults,
    pub t: f64,
    pub coil: Coil,
    pub mag: Magnetic,
    pub theta: f64,
    pub phi: f64,
    pub omega: f64,
    pub torque: f64,
    pub load_cell: f64,
    noise: Noise,
    pwm_phase: f64,
}

impl Plant {
    /// A cold, demagnetised clutch at rest; noise from `seed`.
    pub fn new(p: ClutchParams, seed: u64) -> Self {
        let mag = Magnetic::new(&p.magnetic);
        let theta = p.initial_c;
        let mut s = Self {
            p,
            faults: PlantFaults::default(),
            t: 0.0,
            coil: Coil::default(),
            mag,
            theta,
            phi: 0.0,
            omega: 0.0,
            torque: 0.0,
            load_cell: 0.0,
            noise: Noise::new(seed),
            pwm_phase: 0.0,
        };
        s.omega = s.p.motor.speed(0.0, 0.0);
        s.torque = s.p.fluid.torque(0.0, s.omega, theta);
        s.load_cell = s.torque;
        s
    }

    /// Supply voltage now, V.
    pub fn supply_v(&self) -> f64 {
        self.faults.supply_v.unwrap_or(self.p.coil.supply_v)
    }

    /// Sample the sensors at the present instant.
    pub fn measure(&mut self) -> Measurement {
        let s = &self.p.sensors;
        Measurement {
            hall: s.hall(self.mag.b_hall, self.faults.hall, &mut self.noise),
            current: s.current(self.coil.i_bridge, &mut self.noise),
            supply_v: self.supply_v(),
            temperature: s.temperature(self.theta, &mut self.noise),
        }
    }

    /// Hall counts of the healthy sensor (for a stuck-at fault at the present value).
    pub fn hall_now(&mut self) -> u16 {
        self.p.sensors.hall(self.mag.b_hall, HallFault::None, &mut self.noise)
    }

    /// Advance `dt` seconds with bridge duty `duty` (`enabled` false = all switches off).
    pub fn advance(&mut self, duty: f64, enabled: bool, dt: f64) {
        let subs = self.p.pwm_substeps.max(1) as f64;
        let h_nom = 1.0 / (self.p.coil.pwm_hz * subs);
        let n = (dt / h_nom).round().max(1.0) as usize;
        let h = dt / n as f64;
        let drive = Drive { duty, enabled, supply_v: self.supply_v() };
        for _ in 0..n {
            self.coil.step(&self.p.coil, self.faults.coil, drive, self.theta, self.pwm_phase, h);
            self.pwm_phase = (self.pwm_phase + h * self.p.coil.pwm_hz).fract();
            self.mag.step(&self.p.magnetic, self.coil.i, h);
        }
        self.t += dt;
        self.omega = self.p.motor.speed(self.t, self.phi);
        self.phi += self.omega * dt;
        self.torque = self.p.fluid.torque(self.mag.b_fluid, self.omega, self.theta);
        let r = self.p.coil.r20 * (1.0 + self.p.coil.alpha_cu * (self.theta - 20.0));
        let power = self.torque * self.omega + self.coil.i * self.coil.i * r;
        self.theta = self.p.thermal.step(self.theta, power, self.p.ambient_c, dt);
        self.load_cell = self.p.sensors.load_cell(self.load_cell, self.torque, dt, &mut self.noise);
    }
}
