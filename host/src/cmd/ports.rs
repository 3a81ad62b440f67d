//! `margemu ports`: list the serial ports this machine offers.

use anyhow::{Context, Result};

#[derive(clap::Args)]
pub struct Cmd {}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let ports = serialport::available_ports().context("listing serial ports")?;
        if ports.is_empty() {
            println!(
                "no serial ports found (a pseudo-terminal is not listed: pass its path to --port)"
            );
        }
        for p in ports {
            let kind = match p.port_type {
                serialport::SerialPortType::UsbPort(u) => format!(
                    "USB {:04x}:{:04x} {} {}",
                    u.vid,
                    u.pid,
                    u.manufacturer.unwrap_or_default(),
                    u.product.unwrap_or_default()
                ),
                serialport::SerialPortType::PciPort => "PCI".into(),
                serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
                serialport::SerialPortType::Unknown => "unknown".into(),
            };
            println!("{}\t{}", p.port_name, kind.trim());
        }
        Ok(())
    }
}
