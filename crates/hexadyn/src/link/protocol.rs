//! The master/slave packets of the AMRU5 link (thesis Section 2.3.2, "Network Load"): the
//! 36-byte command packet the master broadcasts every control period and the 20-byte packet
//! each of the six slave boards sends back. The thesis gives the sizes; the layout below is
//! ours and is defined here only (docs/protocol.md describes it for firmware writers, the
//! Python mirror `hexadyn.link.packets` encodes it byte for byte).
//!
//! Two kinds of packets share this layout, told apart by their protocol version
//! ([`Protocol`]): version 3 carries PWM duties to DC motors and encoder counts back (AMRU5,
//! serial legs under the master's PI); version 4 carries goal positions to position servos and
//! their present positions back (a Dynamixel bus behind each leg's board, beyond the thesis).
//! Versions 1 and 2 were the same packets without the run number: a board of either side
//! refuses the other's.
//! A command word's 12 low bits are a [`Setpoint`] of either kind ([`Duty`], [`Goal`]); the
//! header, the sequence numbers and the CRCs are the same.
//!
//! Everything is little-endian. The wire structs are `zerocopy` types: a datagram of the right
//! size is viewed in place, every field read through its byte-order type, and the sizes are
//! checked at compile time.
//!
//! **Command packet** (36 bytes): 18 16-bit words, word k for motor k = 3 leg + (0: q_r,
//! 1: q_v, 2: q_h). Bits 0-9: the PWM duty (0..1023, the 10-bit PWM of the LMD18200
//! H-bridges); bit 10: the direction (1: negative voltage); bit 11: reserved, 0; bits 12-15: a
//! nibble of the 9-byte header, header byte j = nibble(2j) | nibble(2j+1) << 4: bytes 0-1 the
//! sequence number (u16), byte 2 the protocol version, bytes 3-4 the CRC-16 (u16), bytes 5-8
//! the run number (u32) the master chose at its start, which the slaves check (with the
//! master's address) against the run of their handshake ([`super::slave`]). The CRC-16/IBM-3740 (CCITT, poly 0x1021, init 0xFFFF) covers the 36 bytes with
//! the CRC's own four nibbles (bits 12-15 of words 6-9) taken as 0. With the CRC spread over
//! nibbles, this polynomial at these words still catches every corrupted byte and every error
//! of at most 3 bits (checked exhaustively over the error syndromes in the tests).
//!
//! **Slave packet** (20 bytes): byte 0 version << 4 | leg; bytes 1-2 the sequence number of the
//! command it answers (u16); bytes 3-11 the three encoder counts (q_r, q_v, q_h; signed 24-bit,
//! 500 counts per motor revolution, Section 2.3.2); bytes 12-17 the three motor currents
//! (i16, mA); byte 18 the supply voltage (u8, 0.1 V); byte 19 the CRC-8/AUTOSAR of bytes 0-18.
//!
//! **Servo variant** (version 4): command word bits 0-10 a servo's goal position in its
//! position register's counts (0..2047), bit 11 its torque enable; the slave packet's three
//! 24-bit fields hold the servos' present positions in the same counts (0..2047) and its
//! currents the servos' present currents.
//!
//! Parsers check, in this order, the size, the CRC, the version and the value ranges, and
//! return a [`PacketError`]; they never panic on any input.

use std::fmt;

use crc::{Crc, CRC_16_IBM_3740, CRC_8_AUTOSAR};
use zerocopy::byteorder::little_endian::{I16, U16};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

use crate::hexapod::{JOINTS, LEG_COUNT};

/// Protocol version of AMRU5's packets (motor duties, encoder counts).
pub const PROTOCOL_VERSION: u8 = Protocol::Motors.version();
/// Size of the command packet (Section 2.3.2: "a 36 bytes buffer").
pub const COMMAND_SIZE: usize = 36;
/// Size of a slave packet (Section 2.3.2: "a 20 bytes buffer per slave").
pub const REPLY_SIZE: usize = 20;
/// Full-scale PWM duty of the 10-bit PWM (Section 2.3.2, task 3 of the slave board).
pub const DUTY_MAX: u16 = 1023;
/// Current of one least significant bit (A): currents travel in mA.
pub const CURRENT_LSB_A: f64 = 1e-3;
/// Largest |current| a slave packet may carry (mA): the nominal range of the LEM LA 25-NP
/// current transducer (Section 2.3.2, Fig. B.3), ±25 A.
pub const CURRENT_MAX_MA: i16 = 25_000;
/// Supply voltage of one least significant bit (V).
pub const SUPPLY_LSB_V: f64 = 0.1;
/// Range of a signed 24-bit encoder count.
pub const COUNT_MIN: i32 = -(1 << 23);
pub const COUNT_MAX: i32 = (1 << 23) - 1;
/// Largest servo position (goal or present) in the servo variant: 11 bits.
pub const GOAL_MAX: u16 = 0x07FF;
/// Size of the receive buffers: larger than any UDP datagram over IPv4 (at most 65 507 bytes of
/// payload), so that a datagram is never cut and a rejected one is logged with its true size.
pub const RECEIVE_BUFFER: usize = 65_536;

const DUTY_MASK: u16 = 0x03FF;
const DIRECTION_BIT: u16 = 1 << 10;
const RESERVED_BIT: u16 = 1 << 11;
/// A servo command word's torque enable (the servo variant's bit 11).
const TORQUE_BIT: u16 = 1 << 11;
/// The setpoint bits of a command word (below the header nibble).
const SETPOINT_MASK: u16 = 0x0FFF;
const NIBBLE_SHIFT: u16 = 12;
/// Header bytes spread over the top nibbles of the 18 command words.
const HEADER_BYTES: usize = JOINTS / 2;
const HEADER_SEQ: usize = 0;
const HEADER_VERSION: usize = 2;
const HEADER_CRC: usize = 3;
const HEADER_RUN: usize = 5;
/// The command words whose top nibbles hold the CRC-16.
const CRC_WORDS: [usize; 4] = [2 * HEADER_CRC, 2 * HEADER_CRC + 1, 2 * HEADER_CRC + 2, 2 * HEADER_CRC + 3];

const CRC8: Crc<u8> = Crc::<u8>::new(&CRC_8_AUTOSAR);
const CRC16: Crc<u16> = Crc::<u16>::new(&CRC_16_IBM_3740);

/// What the packets carry, told apart by the protocol version (the command header's byte 2,
/// the slave packet's high nibble of byte 0): a board of one kind rejects the other's packets
/// as [`PacketError::Version`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Protocol {
    /// Version 3: PWM duties to DC motors, encoder counts back (AMRU5's boards, Section 2.3.2).
    Motors,
    /// Version 4: goal positions to position servos, their present positions back.
    Servos,
}

impl Protocol {
    pub const fn version(self) -> u8 {
        match self {
            Protocol::Motors => 3,
            Protocol::Servos => 4,
        }
    }

    /// The packets of protocol `version`, if this side speaks it.
    pub const fn of_version(version: u8) -> Option<Protocol> {
        match version {
            3 => Some(Protocol::Motors),
            4 => Some(Protocol::Servos),
            _ => None,
        }
    }

    /// The range of the slave packet's three position fields, with its description for errors.
    fn counts(self) -> (i32, i32, &'static str) {
        match self {
            Protocol::Motors => (COUNT_MIN, COUNT_MAX, "a signed 24-bit encoder count"),
            Protocol::Servos => (0, GOAL_MAX as i32, "0..2047 (an 11-bit servo position)"),
        }
    }
}

// =============================================================================================
// Wire layout
// =============================================================================================

/// The command packet as it is on the wire.
#[derive(FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned, Clone, Copy)]
#[repr(C)]
struct CommandPacket {
    words: [U16; JOINTS],
}

/// A signed 24-bit little-endian integer (the encoder counts).
#[derive(FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned, Clone, Copy)]
#[repr(transparent)]
struct I24([u8; 3]);

impl I24 {
    fn get(self) -> i32 {
        let [a, b, c] = self.0;
        i32::from_le_bytes([a, b, c, if c & 0x80 == 0 { 0 } else { 0xFF }])
    }

    /// `v` within [`COUNT_MIN`, `COUNT_MAX`].
    fn new(v: i32) -> Self {
        let [a, b, c, _] = v.to_le_bytes();
        I24([a, b, c])
    }
}

/// A slave packet as it is on the wire.
#[derive(FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned, Clone, Copy)]
#[repr(C)]
struct ReplyPacket {
    version_leg: u8,
    seq: U16,
    counts: [I24; 3],
    currents: [I16; 3],
    supply: u8,
    crc: u8,
}

const _: () = assert!(size_of::<CommandPacket>() == COMMAND_SIZE);
const _: () = assert!(size_of::<ReplyPacket>() == REPLY_SIZE);
const _: () = assert!(size_of::<I24>() == 3);

// =============================================================================================
// Errors
// =============================================================================================

/// Why a datagram was rejected.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PacketError {
    /// Not the size of the packet.
    Size { expected: usize, got: usize },
    /// The CRC does not match the content (corrupted bytes).
    Checksum { computed: u16, received: u16 },
    /// A protocol version this master or slave does not speak (`got`), not `expected`.
    Version { got: u8, expected: u8 },
    /// A field outside its range.
    OutOfRange { field: &'static str, value: i64, allowed: &'static str },
}

impl fmt::Display for PacketError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PacketError::Size { expected, got } => write!(f, "{got} bytes, expected {expected}"),
            PacketError::Checksum { computed, received } => write!(f, "CRC {received:#06x} does not match the content ({computed:#06x}): corrupted"),
            PacketError::Version { got, expected } => write!(f, "protocol version {got}, this side speaks {expected}"),
            PacketError::OutOfRange { field, value, allowed } => write!(f, "{field} = {value} out of range; allowed: {allowed}"),
        }
    }
}

impl std::error::Error for PacketError {}

/// Rejected datagrams counted by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PacketErrorCounts {
    pub size: u64,
    pub checksum: u64,
    pub version: u64,
    pub range: u64,
}

impl PacketErrorCounts {
    pub fn count(&mut self, e: &PacketError) {
        match e {
            PacketError::Size { .. } => self.size += 1,
            PacketError::Checksum { .. } => self.checksum += 1,
            PacketError::Version { .. } => self.version += 1,
            PacketError::OutOfRange { .. } => self.range += 1,
        }
    }

    pub fn total(&self) -> u64 {
        self.size + self.checksum + self.version + self.range
    }
}

// =============================================================================================
// Commands
// =============================================================================================

/// What a command word carries in its 12 low bits, one per joint: the kind of the packets.
/// The default is the stop (0 V, or the servo's torque off): the zero command.
pub trait Setpoint: Copy + Default + fmt::Debug + PartialEq + Eq + Send + 'static {
    /// The packets that carry it.
    const PROTOCOL: Protocol;
    /// Its 12 bits (bits 0-11 of the command word).
    fn bits(self) -> u16;
    /// The setpoint in bits 0-11 of a command `word`, or why they are none.
    fn from_word(word: u16) -> Result<Self, PacketError>;
}

/// A motor command: the signed 10-bit PWM duty, −1023..=1023 (sign: the direction input of the
/// LMD18200, magnitude: its PWM input).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Duty(i16);

impl Setpoint for Duty {
    const PROTOCOL: Protocol = Protocol::Motors;

    fn bits(self) -> u16 {
        self.0.unsigned_abs() | if self.0 < 0 { DIRECTION_BIT } else { 0 }
    }

    fn from_word(w: u16) -> Result<Self, PacketError> {
        if w & RESERVED_BIT != 0 {
            return Err(PacketError::OutOfRange { field: "command word bit 11 (reserved)", value: i64::from(w), allowed: "bit 11 clear" });
        }
        // Ten bits cannot exceed 1023: every duty field is in range.
        let magnitude = (w & DUTY_MASK) as i16;
        Ok(Duty(if w & DIRECTION_BIT == 0 { magnitude } else { -magnitude }))
    }
}

/// A servo command (the servo variant): bits 0-10 the goal position in counts of the servo's
/// position register (0..2047; the Goal Position of a Dynamixel), bit 11 the torque enable
/// (0: the servo's torque off, its goal ignored). The default, all bits 0, is the stop.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Goal(u16);

impl Goal {
    /// Torque off.
    pub const OFF: Goal = Goal(0);

    /// Holding `register` (0..=2047) with the torque on.
    pub fn position(register: u16) -> Option<Goal> {
        (register <= GOAL_MAX).then_some(Goal(register | TORQUE_BIT))
    }

    /// The goal register with the torque on; `None` with the torque off.
    pub fn register(self) -> Option<u16> {
        (self.0 & TORQUE_BIT != 0).then_some(self.0 & GOAL_MAX)
    }
}

impl Setpoint for Goal {
    const PROTOCOL: Protocol = Protocol::Servos;

    fn bits(self) -> u16 {
        self.0
    }

    /// Any 12 bits are a goal: a goal with the torque off is ignored by the servo.
    fn from_word(w: u16) -> Result<Self, PacketError> {
        Ok(Goal(w & SETPOINT_MASK))
    }
}

impl Duty {
    pub const ZERO: Duty = Duty(0);

    /// `d` if |d| <= 1023.
    pub fn new(d: i16) -> Option<Duty> {
        (d.unsigned_abs() <= DUTY_MAX).then_some(Duty(d))
    }

    pub fn get(self) -> i16 {
        self.0
    }

    /// The duty that applies `voltage` (V) from a supply of `supply` (V): round(u / U · 1023),
    /// saturated at full scale. No supply, or a voltage that is not a number, gives 0.
    pub fn from_voltage(voltage: f64, supply: f64) -> Duty {
        if !(supply > 0.0) || !voltage.is_finite() {
            return Duty::ZERO;
        }
        let full = f64::from(DUTY_MAX);
        Duty((voltage / supply * full).round().clamp(-full, full) as i16)
    }

    /// The mean voltage the H-bridge applies with this duty from a supply of `supply` (V).
    pub fn voltage(self, supply: f64) -> f64 {
        f64::from(self.0) / f64::from(DUTY_MAX) * supply
    }
}

/// The content of a command packet: the sequence number of the period, the master's run number
/// and the 18 setpoints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Commands<S> {
    pub seq: u16,
    /// The number the master chose at its start: the slaves follow one run of one master.
    pub run: u32,
    pub setpoints: [S; JOINTS],
}

/// A command packet of version 3: 18 motor duties.
pub type MotorCommands = Commands<Duty>;
/// A command packet of version 4: 18 servo goals.
pub type ServoCommands = Commands<Goal>;

/// The CRC of a command packet: over its bytes with the CRC nibbles (words 6-9) cleared.
fn command_crc(bytes: &[u8; COMMAND_SIZE]) -> u16 {
    let mut b = *bytes;
    for word in CRC_WORDS {
        b[2 * word + 1] &= 0x0F;
    }
    CRC16.checksum(&b)
}

/// Writes the CRC-16 into the top nibbles of words 6-9 (low nibble first).
fn put_command_crc(bytes: &mut [u8; COMMAND_SIZE], crc: u16) {
    for (i, word) in CRC_WORDS.into_iter().enumerate() {
        bytes[2 * word + 1] = (bytes[2 * word + 1] & 0x0F) | (((crc >> (4 * i)) & 0x0F) as u8) << 4;
    }
}

impl<S: Setpoint> Commands<S> {
    /// The stop: every motor at 0 V, or every servo's torque off (also the handshake).
    pub fn zero(seq: u16, run: u32) -> Self {
        Commands { seq, run, setpoints: [S::default(); JOINTS] }
    }

    /// Whether it is the zero command.
    pub fn is_zero(&self) -> bool {
        self.setpoints.iter().all(|s| *s == S::default())
    }

    pub fn encode(&self) -> [u8; COMMAND_SIZE] {
        let mut header = [0u8; HEADER_BYTES];
        header[HEADER_SEQ..HEADER_SEQ + 2].copy_from_slice(&self.seq.to_le_bytes());
        header[HEADER_VERSION] = S::PROTOCOL.version();
        header[HEADER_RUN..].copy_from_slice(&self.run.to_le_bytes());
        let mut packet = CommandPacket { words: [U16::ZERO; JOINTS] };
        for (k, (word, setpoint)) in packet.words.iter_mut().zip(self.setpoints).enumerate() {
            *word = U16::new((setpoint.bits() & SETPOINT_MASK) | u16::from(nibble(&header, k)) << NIBBLE_SHIFT);
        }
        let mut bytes = [0u8; COMMAND_SIZE];
        bytes.copy_from_slice(packet.as_bytes());
        let crc = command_crc(&bytes);
        put_command_crc(&mut bytes, crc);
        bytes
    }

    pub fn decode(bytes: &[u8]) -> Result<Self, PacketError> {
        let packet = CommandPacket::ref_from_bytes(bytes).map_err(|_| PacketError::Size { expected: COMMAND_SIZE, got: bytes.len() })?;
        let words = packet.words.map(|w| w.get());
        let mut header = [0u8; HEADER_BYTES];
        for (k, w) in words.iter().enumerate() {
            header[k / 2] |= ((w >> NIBBLE_SHIFT) as u8) << (4 * (k % 2));
        }
        let raw: &[u8; COMMAND_SIZE] = packet.as_bytes().try_into().map_err(|_| PacketError::Size { expected: COMMAND_SIZE, got: bytes.len() })?;
        let computed = command_crc(raw);
        let received = u16::from_le_bytes([header[HEADER_CRC], header[HEADER_CRC + 1]]);
        if computed != received {
            return Err(PacketError::Checksum { computed, received });
        }
        let expected = S::PROTOCOL.version();
        if header[HEADER_VERSION] != expected {
            return Err(PacketError::Version { got: header[HEADER_VERSION], expected });
        }
        let mut setpoints = [S::default(); JOINTS];
        for (s, &w) in setpoints.iter_mut().zip(&words) {
            *s = S::from_word(w)?;
        }
        let run = u32::from_le_bytes(std::array::from_fn(|i| header[HEADER_RUN + i]));
        Ok(Commands { seq: u16::from_le_bytes([header[HEADER_SEQ], header[HEADER_SEQ + 1]]), run, setpoints })
    }
}

/// Nibble k of the header (low nibble of byte k/2 for even k, high nibble for odd k).
fn nibble(header: &[u8; HEADER_BYTES], k: usize) -> u8 {
    (header[k / 2] >> (4 * (k % 2))) & 0x0F
}

// =============================================================================================
// Slave packets
// =============================================================================================

/// The content of a slave packet: what the board of one leg measured when it applied the
/// command of period `seq` (Section 2.3.2, Fig. 2.19), in its raw units. Its protocol is that
/// of the commands it answers: encode and decode take it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlaveReply {
    /// Leg 0..5 (the board).
    pub leg: u8,
    /// Sequence number of the command this packet answers.
    pub seq: u16,
    /// The three joints' position counts: encoder counts of q_r, q_v, q_h (500 per motor
    /// revolution), [`COUNT_MIN`, `COUNT_MAX`]; with servos their present position registers,
    /// 0..=[`GOAL_MAX`].
    pub counts: [i32; 3],
    /// Motor currents (mA), |i| <= [`CURRENT_MAX_MA`].
    pub currents_ma: [i16; 3],
    /// Supply voltage in units of [`SUPPLY_LSB_V`].
    pub supply: u8,
}

impl SlaveReply {
    /// A packet of `protocol` from measurements in SI units, saturated as the board's counters
    /// and A/D converters saturate: counts to 24 bits (servo positions to 0..2047), currents to
    /// ±25 A, the supply to 0..25.5 V. `leg` is taken modulo 6.
    pub fn measured(protocol: Protocol, leg: usize, seq: u16, counts: [i64; 3], currents_a: [f64; 3], supply_v: f64) -> Self {
        let max = f64::from(CURRENT_MAX_MA);
        let (low, high, _) = protocol.counts();
        SlaveReply {
            leg: (leg % LEG_COUNT) as u8,
            seq,
            counts: counts.map(|c| c.clamp(i64::from(low), i64::from(high)) as i32),
            // NaN saturates to 0 in the cast.
            currents_ma: currents_a.map(|i| (i / CURRENT_LSB_A).round().clamp(-max, max) as i16),
            supply: (supply_v / SUPPLY_LSB_V).round().clamp(0.0, 255.0) as u8,
        }
    }

    /// Motor currents (A).
    pub fn currents(&self) -> [f64; 3] {
        self.currents_ma.map(|i| f64::from(i) / 1000.0)
    }

    /// Supply voltage (V), exactly the decimal written (12.0 for 120).
    pub fn supply_voltage(&self) -> f64 {
        f64::from(self.supply) / 10.0
    }

    /// The packet of `protocol`; fields outside their ranges are saturated to them (use
    /// [`Self::measured`] or [`Self::decode`] to build a valid one).
    pub fn encode(&self, protocol: Protocol) -> [u8; REPLY_SIZE] {
        let (low, high, _) = protocol.counts();
        let mut p = ReplyPacket {
            version_leg: protocol.version() << 4 | (self.leg % LEG_COUNT as u8),
            seq: U16::new(self.seq),
            counts: self.counts.map(|c| I24::new(c.clamp(low, high))),
            currents: self.currents_ma.map(|i| I16::new(i.clamp(-CURRENT_MAX_MA, CURRENT_MAX_MA))),
            supply: self.supply,
            crc: 0,
        };
        p.crc = CRC8.checksum(&p.as_bytes()[..REPLY_SIZE - 1]);
        let mut bytes = [0u8; REPLY_SIZE];
        bytes.copy_from_slice(p.as_bytes());
        bytes
    }

    /// The packet of `protocol` in `bytes`, or why they are none.
    pub fn decode(bytes: &[u8], protocol: Protocol) -> Result<Self, PacketError> {
        let p = ReplyPacket::ref_from_bytes(bytes).map_err(|_| PacketError::Size { expected: REPLY_SIZE, got: bytes.len() })?;
        let computed = CRC8.checksum(&p.as_bytes()[..REPLY_SIZE - 1]);
        if computed != p.crc {
            return Err(PacketError::Checksum { computed: computed.into(), received: p.crc.into() });
        }
        let (version, expected) = (p.version_leg >> 4, protocol.version());
        if version != expected {
            return Err(PacketError::Version { got: version, expected });
        }
        let leg = p.version_leg & 0x0F;
        if usize::from(leg) >= LEG_COUNT {
            return Err(PacketError::OutOfRange { field: "leg", value: i64::from(leg), allowed: "0..5" });
        }
        let counts = p.counts.map(I24::get);
        let (low, high, allowed) = protocol.counts();
        if let Some(&c) = counts.iter().find(|&&c| !(low..=high).contains(&c)) {
            return Err(PacketError::OutOfRange { field: "position count", value: i64::from(c), allowed });
        }
        let currents_ma = p.currents.map(|i| i.get());
        if let Some(&i) = currents_ma.iter().find(|i| i.unsigned_abs() > CURRENT_MAX_MA as u16) {
            return Err(PacketError::OutOfRange { field: "motor current (mA)", value: i64::from(i), allowed: "-25000..25000 (the ±25 A of the current transducer)" });
        }
        Ok(SlaveReply { leg, seq: p.seq.get(), counts, currents_ma, supply: p.supply })
    }
}

/// Sequence numbers compared modulo 2^16 (serial number arithmetic): how many periods `seq`
/// is after `reference` (negative: before), within ±32768.
pub fn seq_distance(seq: u16, reference: u16) -> i32 {
    i32::from(seq.wrapping_sub(reference) as i16)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn any_duty() -> impl Strategy<Value = Duty> {
        (-1023i16..=1023).prop_map(Duty)
    }

    fn any_commands() -> impl Strategy<Value = MotorCommands> {
        (any::<u16>(), any::<u32>(), proptest::array::uniform18(any_duty())).prop_map(|(seq, run, setpoints)| MotorCommands { seq, run, setpoints })
    }

    fn any_servo_commands() -> impl Strategy<Value = ServoCommands> {
        (any::<u16>(), any::<u32>(), proptest::array::uniform18((0u16..=SETPOINT_MASK).prop_map(Goal))).prop_map(|(seq, run, setpoints)| ServoCommands { seq, run, setpoints })
    }

    fn any_reply_of(protocol: Protocol) -> impl Strategy<Value = SlaveReply> {
        let (low, high, _) = protocol.counts();
        (0u8..6, any::<u16>(), proptest::array::uniform3(low..=high), proptest::array::uniform3(-CURRENT_MAX_MA..=CURRENT_MAX_MA), any::<u8>())
            .prop_map(|(leg, seq, counts, currents_ma, supply)| SlaveReply { leg, seq, counts, currents_ma, supply })
    }

    fn any_reply() -> impl Strategy<Value = SlaveReply> {
        any_reply_of(Protocol::Motors)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        #[test]
        fn commands_round_trip(c in any_commands()) {
            prop_assert_eq!(MotorCommands::decode(&c.encode()), Ok(c));
        }

        #[test]
        fn replies_round_trip(r in any_reply()) {
            prop_assert_eq!(SlaveReply::decode(&r.encode(Protocol::Motors), Protocol::Motors), Ok(r));
        }

        /// The servo variant round-trips, and a board of either kind rejects the other's
        /// packets by their version.
        #[test]
        fn servo_packets_round_trip_and_are_not_motor_packets(c in any_servo_commands(), r in any_reply_of(Protocol::Servos)) {
            let bytes = c.encode();
            prop_assert_eq!(ServoCommands::decode(&bytes), Ok(c));
            prop_assert_eq!(MotorCommands::decode(&bytes), Err(PacketError::Version { got: 4, expected: 3 }));
            let reply = r.encode(Protocol::Servos);
            prop_assert_eq!(SlaveReply::decode(&reply, Protocol::Servos), Ok(r));
            prop_assert_eq!(SlaveReply::decode(&reply, Protocol::Motors), Err(PacketError::Version { got: 4, expected: 3 }));
            let motor = MotorCommands::zero(c.seq, c.run).encode();
            prop_assert_eq!(ServoCommands::decode(&motor), Err(PacketError::Version { got: 3, expected: 4 }));
        }

        /// Any one byte of a valid packet changed is caught by the CRC-8 (a burst of at most 8
        /// bits): a corrupted byte never decodes.
        #[test]
        fn one_corrupted_byte_is_caught(c in any_commands(), g in any_servo_commands(), r in any_reply(), at in 0usize..36, x in 1u8..=255) {
            let mut b = c.encode();
            b[at] ^= x;
            let caught = matches!(MotorCommands::decode(&b), Err(PacketError::Checksum { .. }));
            prop_assert!(caught, "command byte {} ^ {}", at, x);
            let mut b = g.encode();
            b[at] ^= x;
            let caught = matches!(ServoCommands::decode(&b), Err(PacketError::Checksum { .. }));
            prop_assert!(caught, "servo command byte {} ^ {}", at, x);
            for protocol in [Protocol::Motors, Protocol::Servos] {
                let mut b = SlaveReply { counts: r.counts.map(|c| c & i32::from(GOAL_MAX)), ..r }.encode(protocol);
                b[at % REPLY_SIZE] ^= x;
                let caught = matches!(SlaveReply::decode(&b, protocol), Err(PacketError::Checksum { .. }));
                prop_assert!(caught, "reply byte {} ^ {} ({:?})", at % REPLY_SIZE, x, protocol);
            }
        }

        /// Whatever a decoder accepts encodes back to the same bytes.
        #[test]
        fn accepted_bytes_are_canonical(bytes in proptest::collection::vec(any::<u8>(), 0..48)) {
            if let Ok(c) = MotorCommands::decode(&bytes) {
                prop_assert_eq!(&c.encode()[..], &bytes[..]);
            }
            if let Ok(c) = ServoCommands::decode(&bytes) {
                prop_assert_eq!(&c.encode()[..], &bytes[..]);
            }
            for protocol in [Protocol::Motors, Protocol::Servos] {
                if let Ok(r) = SlaveReply::decode(&bytes, protocol) {
                    prop_assert_eq!(&r.encode(protocol)[..], &bytes[..]);
                }
            }
        }
    }

    /// The fuzz target of the link: 10^6 arbitrary datagrams (any size 0..64, then packets with
    /// their CRC fixed so that the version and range checks are reached too) through the
    /// parsers of both kinds, with no panic; every rejection is counted under one kind.
    #[test]
    fn a_million_arbitrary_datagrams_never_panic() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let mut counts = PacketErrorCounts::default();
        let (mut accepted, mut inputs) = (0u64, 0u64);
        let mut buf = [0u8; 64];
        for n in 0..1_000_000u32 {
            let len = match n % 4 {
                0 => rng.random_range(0..64),
                1 => COMMAND_SIZE,
                _ => REPLY_SIZE,
            };
            rng.fill(&mut buf[..len]);
            let bytes = &mut buf[..len];
            // Half of the right-size inputs get a valid CRC: the later checks see them.
            if n % 2 == 1 && len == REPLY_SIZE {
                bytes[REPLY_SIZE - 1] = CRC8.checksum(&bytes[..REPLY_SIZE - 1]);
            }
            if len == COMMAND_SIZE && n % 8 == 1 {
                let mut b = [0u8; COMMAND_SIZE];
                b.copy_from_slice(bytes);
                let crc = command_crc(&b);
                put_command_crc(&mut b, crc);
                bytes.copy_from_slice(&b);
            }
            // Half of the version nibbles forged to one of the two kinds.
            if len == REPLY_SIZE && n % 4 == 3 {
                bytes[0] = (Protocol::Motors.version() + (n / 4 % 2) as u8) << 4 | (bytes[0] & 0x0F);
                bytes[REPLY_SIZE - 1] = CRC8.checksum(&bytes[..REPLY_SIZE - 1]);
            }
            let results = [
                MotorCommands::decode(bytes).map(|_| ()),
                ServoCommands::decode(bytes).map(|_| ()),
                SlaveReply::decode(bytes, Protocol::Motors).map(|_| ()),
                SlaveReply::decode(bytes, Protocol::Servos).map(|_| ()),
            ];
            for result in results {
                inputs += 1;
                match result {
                    Ok(()) => accepted += 1,
                    Err(e) => counts.count(&e),
                }
            }
        }
        assert_eq!(inputs, 4_000_000);
        assert_eq!(counts.total() + accepted, inputs);
        // Every check was exercised.
        assert!(counts.size > 0 && counts.checksum > 0 && counts.version > 0 && counts.range > 0 && accepted > 0, "{counts:?}, {accepted} accepted");
    }

    /// The command CRC is linear: an error pattern goes undetected iff the XOR of the
    /// syndromes of its bits is 0. Every corrupted byte (255 patterns at each of the 36
    /// positions) and every error of 1, 2 or 3 bits has a non-zero syndrome.
    #[test]
    fn command_crc_catches_every_byte_and_three_bit_error() {
        let clean = MotorCommands::zero(0, 0).encode();
        let syndrome = |flip: &dyn Fn(&mut [u8; COMMAND_SIZE])| {
            let mut b = clean;
            flip(&mut b);
            let received = (0..4).fold(0u16, |acc, i| acc | u16::from(b[2 * CRC_WORDS[i] + 1] >> 4) << (4 * i));
            command_crc(&b) ^ received
        };
        let bits: Vec<u16> = (0..8 * COMMAND_SIZE).map(|i| syndrome(&|b| b[i / 8] ^= 1 << (i % 8))).collect();
        for at in 0..COMMAND_SIZE {
            for x in 1..=255u8 {
                let s = (0..8).filter(|k| x >> k & 1 == 1).fold(0, |acc, k| acc ^ bits[8 * at + k]);
                assert_ne!(s, 0, "byte {at} ^ {x:#04x} undetected");
            }
        }
        let set: std::collections::HashMap<u16, usize> = bits.iter().enumerate().map(|(i, &s)| (s, i)).collect();
        assert_eq!(set.len(), bits.len(), "two single-bit errors share a syndrome");
        assert!(!set.contains_key(&0));
        for i in 0..bits.len() {
            for j in i + 1..bits.len() {
                if let Some(&k) = set.get(&(bits[i] ^ bits[j])) {
                    assert!(k == i || k == j, "bits {i}, {j}, {k} undetected");
                }
            }
        }
    }

    #[test]
    fn known_layout() {
        // Seq 0x1234, version 3, run 0x89ABCDEF: header 34 12 03 crc crc ef cd ab 89; duty +5
        // on motor 0, -1023 on motor 17.
        let mut duties = [Duty::ZERO; JOINTS];
        duties[0] = Duty(5);
        duties[17] = Duty(-1023);
        let b = MotorCommands { seq: 0x1234, run: 0x89AB_CDEF, setpoints: duties }.encode();
        let nibbles: Vec<u16> = (0..JOINTS).map(|k| u16::from_le_bytes([b[2 * k], b[2 * k + 1]]) >> 12).collect();
        assert_eq!(u16::from_le_bytes([b[0], b[1]]), 0x4005); // nibble 0 = 4 (seq low nibble), duty 5
        assert_eq!(nibbles[1..6], [0x3, 0x2, 0x1, 0x3, 0x0]); // seq, version 3
        assert_eq!(nibbles[10..], [0xF, 0xE, 0xD, 0xC, 0xB, 0xA, 0x9, 0x8]); // run, low nibble first
        assert_eq!(u16::from_le_bytes([b[34], b[35]]) & 0x0FFF, 0x07FF); // direction + 1023
        println!("motor command: {b:02x?}");
        let r = SlaveReply { leg: 3, seq: 0x1234, counts: [-1, 0x123456, 0], currents_ma: [-2, 0, 25_000], supply: 120 }.encode(Protocol::Motors);
        assert_eq!(&r[..12], &[0x33, 0x34, 0x12, 0xFF, 0xFF, 0xFF, 0x56, 0x34, 0x12, 0, 0, 0]);
        println!("motor reply: {r:02x?}");
        assert_eq!(&r[12..19], &[0xFE, 0xFF, 0, 0, 0xA8, 0x61, 120]);
        // The servo variant (docs/protocol.md): goal 512 with the torque on at servo 0, torque
        // off at servo 17; leg 3's present positions 0, 512, 2047.
        let mut goals = [Goal::OFF; JOINTS];
        goals[0] = Goal::position(512).unwrap();
        let b = ServoCommands { seq: 0x1234, run: 0x89AB_CDEF, setpoints: goals }.encode();
        assert_eq!(u16::from_le_bytes([b[0], b[1]]), 0x4A00); // nibble 4, torque on, 512
        assert_eq!(u16::from_le_bytes([b[8], b[9]]) >> 12, 0x4); // version 4
        assert_eq!(u16::from_le_bytes([b[34], b[35]]) & 0x0FFF, 0);
        assert_eq!(Goal::position(2048), None);
        assert_eq!((goals[0].register(), Goal::OFF.register()), (Some(512), None));
        let r = SlaveReply { leg: 3, seq: 0x1234, counts: [0, 512, 2047], currents_ma: [-2, 0, 1500], supply: 111 }.encode(Protocol::Servos);
        assert_eq!(&r[..12], &[0x43, 0x34, 0x12, 0, 0, 0, 0, 0x02, 0, 0xFF, 0x07, 0]);
        println!("servo command: {b:02x?}\nservo reply: {r:02x?}");
        // The catalogue check values of CRC-8/AUTOSAR and CRC-16/IBM-3740.
        assert_eq!(CRC8.checksum(b"123456789"), 0xDF);
        assert_eq!(CRC16.checksum(b"123456789"), 0x29B1);
    }

    #[test]
    fn duty_scaling() {
        assert_eq!(Duty::from_voltage(12.0, 12.0), Duty(1023));
        assert_eq!(Duty::from_voltage(-30.0, 12.0), Duty(-1023));
        assert_eq!(Duty::from_voltage(6.0, 12.0), Duty(512)); // 511.5 rounds away from zero
        assert_eq!(Duty::from_voltage(f64::NAN, 12.0), Duty::ZERO);
        assert_eq!(Duty::from_voltage(1.0, 0.0), Duty::ZERO);
        assert!((Duty(512).voltage(12.0) - 6.005865102639296).abs() < 1e-12);
        let r = SlaveReply::measured(Protocol::Motors, 7, 9, [1 << 30, -5, 0], [0.0015, f64::NAN, -99.0], 12.04);
        assert_eq!((r.leg, r.counts, r.currents_ma, r.supply), (1, [COUNT_MAX, -5, 0], [2, 0, -25_000], 120));
        let servo = SlaveReply::measured(Protocol::Servos, 0, 9, [1 << 30, -5, 300], [0.0; 3], 11.1);
        assert_eq!(servo.counts, [2047, 0, 300]);
        assert_eq!(r.supply_voltage(), 12.0);
    }

    #[test]
    fn rejections_name_their_cause() {
        assert_eq!(SlaveReply::decode(&[0; 19], Protocol::Motors), Err(PacketError::Size { expected: 20, got: 19 }));
        let mut b = SlaveReply { leg: 0, seq: 1, counts: [0; 3], currents_ma: [0; 3], supply: 120 }.encode(Protocol::Motors);
        b[0] = 0x46; // version 4, leg 6
        b[19] = CRC8.checksum(&b[..19]);
        assert_eq!(SlaveReply::decode(&b, Protocol::Motors), Err(PacketError::Version { got: 4, expected: 3 }));
        assert!(matches!(SlaveReply::decode(&b, Protocol::Servos), Err(PacketError::OutOfRange { field: "leg", value: 6, .. })));
        b[0] = 0x36;
        b[19] = CRC8.checksum(&b[..19]);
        assert!(matches!(SlaveReply::decode(&b, Protocol::Motors), Err(PacketError::OutOfRange { field: "leg", value: 6, .. })));
        // A servo position beyond 11 bits (a forged or wrong-kind packet).
        b[0] = 0x40;
        b[3] = 0xFF; // -1 in the first 24-bit field
        b[4] = 0xFF;
        b[5] = 0xFF;
        b[19] = CRC8.checksum(&b[..19]);
        assert!(matches!(SlaveReply::decode(&b, Protocol::Servos), Err(PacketError::OutOfRange { field: "position count", value: -1, .. })));
        assert_eq!(PacketError::Version { got: 4, expected: 3 }.to_string(), "protocol version 4, this side speaks 3");
        // The packets of versions 1 and 2 (before the run number) are refused.
        let mut old = MotorCommands::zero(7, 0).encode();
        old[9] = (old[9] & 0x0F) | 1 << 4; // version nibble 1
        let crc = command_crc(&old);
        put_command_crc(&mut old, crc);
        assert_eq!(MotorCommands::decode(&old), Err(PacketError::Version { got: 1, expected: 3 }));
        assert_eq!((Protocol::of_version(3), Protocol::of_version(4), Protocol::of_version(2)), (Some(Protocol::Motors), Some(Protocol::Servos), None));
        assert_eq!(seq_distance(2, 65534), 4);
        assert_eq!(seq_distance(65534, 2), -4);
    }
}
