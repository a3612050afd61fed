//! The master/slave packets of the AMRU5 link (thesis Section 2.3.2, "Network Load"): the
//! 36-byte command packet the master broadcasts every control period and the 20-byte packet
//! each of the six slave boards sends back. The thesis gives the sizes; the layout below is
//! ours and is defined here only (docs/protocol.md describes it for firmware writers, the
//! Python mirror `hexadyn.link.packets` encodes it byte for byte).
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
//! reserved, 0. The CRC-16/IBM-3740 (CCITT, poly 0x1021, init 0xFFFF) covers the 36 bytes with
//! the CRC's own four nibbles (bits 12-15 of words 6-9) taken as 0. With the CRC spread over
//! nibbles, this polynomial at these words still catches every corrupted byte and every error
//! of at most 3 bits (checked exhaustively over the error syndromes in the tests).
//!
//! **Slave packet** (20 bytes): byte 0 version << 4 | leg; bytes 1-2 the sequence number of the
//! command it answers (u16); bytes 3-11 the three encoder counts (q_r, q_v, q_h; signed 24-bit,
//! 500 counts per motor revolution, Section 2.3.2); bytes 12-17 the three motor currents
//! (i16, mA); byte 18 the supply voltage (u8, 0.1 V); byte 19 the CRC-8/AUTOSAR of bytes 0-18.
//!
//! Parsers check, in this order, the size, the CRC, the version and the value ranges, and
//! return a [`PacketError`]; they never panic on any input.

use std::fmt;

use crc::{Crc, CRC_16_IBM_3740, CRC_8_AUTOSAR};
use zerocopy::byteorder::little_endian::{I16, U16};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

use crate::hexapod::{JOINTS, LEG_COUNT};

/// Protocol version carried by both packets.
pub const PROTOCOL_VERSION: u8 = 1;
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

const DUTY_MASK: u16 = 0x03FF;
const DIRECTION_BIT: u16 = 1 << 10;
const RESERVED_BIT: u16 = 1 << 11;
const NIBBLE_SHIFT: u16 = 12;
/// Header bytes spread over the top nibbles of the 18 command words.
const HEADER_BYTES: usize = JOINTS / 2;
const HEADER_SEQ: usize = 0;
const HEADER_VERSION: usize = 2;
const HEADER_CRC: usize = 3;
/// The command words whose top nibbles hold the CRC-16.
const CRC_WORDS: [usize; 4] = [2 * HEADER_CRC, 2 * HEADER_CRC + 1, 2 * HEADER_CRC + 2, 2 * HEADER_CRC + 3];

const CRC8: Crc<u8> = Crc::<u8>::new(&CRC_8_AUTOSAR);
const CRC16: Crc<u16> = Crc::<u16>::new(&CRC_16_IBM_3740);

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
    /// A protocol version this master or slave does not speak.
    Version(u8),
    /// A field outside its range.
    OutOfRange { field: &'static str, value: i64, allowed: &'static str },
}

impl fmt::Display for PacketError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PacketError::Size { expected, got } => write!(f, "{got} bytes, expected {expected}"),
            PacketError::Checksum { computed, received } => write!(f, "CRC {received:#06x} does not match the content ({computed:#06x}): corrupted"),
            PacketError::Version(v) => write!(f, "protocol version {v}, this side speaks {PROTOCOL_VERSION}"),
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
            PacketError::Version(_) => self.version += 1,
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

/// A motor command: the signed 10-bit PWM duty, −1023..=1023 (sign: the direction input of the
/// LMD18200, magnitude: its PWM input).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Duty(i16);

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

/// The content of a command packet: the sequence number of the period and the 18 duties.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotorCommands {
    pub seq: u16,
    pub duties: [Duty; JOINTS],
}

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

impl MotorCommands {
    /// Every motor at 0 V.
    pub fn zero(seq: u16) -> Self {
        MotorCommands { seq, duties: [Duty::ZERO; JOINTS] }
    }

    pub fn encode(&self) -> [u8; COMMAND_SIZE] {
        let mut header = [0u8; HEADER_BYTES];
        header[HEADER_SEQ..HEADER_SEQ + 2].copy_from_slice(&self.seq.to_le_bytes());
        header[HEADER_VERSION] = PROTOCOL_VERSION;
        let mut packet = CommandPacket { words: [U16::ZERO; JOINTS] };
        for (k, (word, duty)) in packet.words.iter_mut().zip(self.duties).enumerate() {
            let d = duty.0;
            let direction = if d < 0 { DIRECTION_BIT } else { 0 };
            *word = U16::new(d.unsigned_abs() | direction | u16::from(nibble(&header, k)) << NIBBLE_SHIFT);
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
        if header[HEADER_VERSION] != PROTOCOL_VERSION {
            return Err(PacketError::Version(header[HEADER_VERSION]));
        }
        if let Some(&b) = header[HEADER_CRC + 2..].iter().find(|&&b| b != 0) {
            return Err(PacketError::OutOfRange { field: "command header bytes 5-8 (reserved)", value: i64::from(b), allowed: "0" });
        }
        if let Some(w) = words.iter().find(|&&w| w & RESERVED_BIT != 0) {
            return Err(PacketError::OutOfRange { field: "command word bit 11 (reserved)", value: i64::from(*w), allowed: "bit 11 clear" });
        }
        // Ten bits cannot exceed 1023: every duty field is in range.
        let duties = words.map(|w| {
            let magnitude = (w & DUTY_MASK) as i16;
            Duty(if w & DIRECTION_BIT == 0 { magnitude } else { -magnitude })
        });
        Ok(MotorCommands { seq: u16::from_le_bytes([header[HEADER_SEQ], header[HEADER_SEQ + 1]]), duties })
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
/// command of period `seq` (Section 2.3.2, Fig. 2.19), in its raw units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SlaveReply {
    /// Leg 0..5 (the board).
    pub leg: u8,
    /// Sequence number of the command this packet answers.
    pub seq: u16,
    /// Encoder counts of q_r, q_v, q_h (500 per motor revolution), [`COUNT_MIN`, `COUNT_MAX`].
    pub counts: [i32; 3],
    /// Motor currents (mA), |i| <= [`CURRENT_MAX_MA`].
    pub currents_ma: [i16; 3],
    /// Supply voltage in units of [`SUPPLY_LSB_V`].
    pub supply: u8,
}

impl SlaveReply {
    /// A packet from measurements in SI units, saturated as the board's counters and A/D
    /// converters saturate: counts to 24 bits, currents to ±25 A, the supply to 0..25.5 V.
    /// `leg` is taken modulo 6.
    pub fn measured(leg: usize, seq: u16, counts: [i64; 3], currents_a: [f64; 3], supply_v: f64) -> Self {
        let max = f64::from(CURRENT_MAX_MA);
        SlaveReply {
            leg: (leg % LEG_COUNT) as u8,
            seq,
            counts: counts.map(|c| c.clamp(i64::from(COUNT_MIN), i64::from(COUNT_MAX)) as i32),
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

    /// The packet; fields outside their ranges are saturated to them (use [`Self::measured`]
    /// or [`Self::decode`] to build a valid one).
    pub fn encode(&self) -> [u8; REPLY_SIZE] {
        let mut p = ReplyPacket {
            version_leg: PROTOCOL_VERSION << 4 | (self.leg % LEG_COUNT as u8),
            seq: U16::new(self.seq),
            counts: self.counts.map(|c| I24::new(c.clamp(COUNT_MIN, COUNT_MAX))),
            currents: self.currents_ma.map(|i| I16::new(i.clamp(-CURRENT_MAX_MA, CURRENT_MAX_MA))),
            supply: self.supply,
            crc: 0,
        };
        p.crc = CRC8.checksum(&p.as_bytes()[..REPLY_SIZE - 1]);
        let mut bytes = [0u8; REPLY_SIZE];
        bytes.copy_from_slice(p.as_bytes());
        bytes
    }

    pub fn decode(bytes: &[u8]) -> Result<Self, PacketError> {
        let p = ReplyPacket::ref_from_bytes(bytes).map_err(|_| PacketError::Size { expected: REPLY_SIZE, got: bytes.len() })?;
        let computed = CRC8.checksum(&p.as_bytes()[..REPLY_SIZE - 1]);
        if computed != p.crc {
            return Err(PacketError::Checksum { computed: computed.into(), received: p.crc.into() });
        }
        let version = p.version_leg >> 4;
        if version != PROTOCOL_VERSION {
            return Err(PacketError::Version(version));
        }
        let leg = p.version_leg & 0x0F;
        if usize::from(leg) >= LEG_COUNT {
            return Err(PacketError::OutOfRange { field: "leg", value: i64::from(leg), allowed: "0..5" });
        }
        let currents_ma = p.currents.map(|i| i.get());
        if let Some(&i) = currents_ma.iter().find(|i| i.unsigned_abs() > CURRENT_MAX_MA as u16) {
            return Err(PacketError::OutOfRange { field: "motor current (mA)", value: i64::from(i), allowed: "-25000..25000 (the ±25 A of the current transducer)" });
        }
        Ok(SlaveReply { leg, seq: p.seq.get(), counts: p.counts.map(I24::get), currents_ma, supply: p.supply })
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
        (any::<u16>(), proptest::array::uniform18(any_duty())).prop_map(|(seq, duties)| MotorCommands { seq, duties })
    }

    fn any_reply() -> impl Strategy<Value = SlaveReply> {
        (0u8..6, any::<u16>(), proptest::array::uniform3(COUNT_MIN..=COUNT_MAX), proptest::array::uniform3(-CURRENT_MAX_MA..=CURRENT_MAX_MA), any::<u8>())
            .prop_map(|(leg, seq, counts, currents_ma, supply)| SlaveReply { leg, seq, counts, currents_ma, supply })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        #[test]
        fn commands_round_trip(c in any_commands()) {
            prop_assert_eq!(MotorCommands::decode(&c.encode()), Ok(c));
        }

        #[test]
        fn replies_round_trip(r in any_reply()) {
            prop_assert_eq!(SlaveReply::decode(&r.encode()), Ok(r));
        }

        /// Any one byte of a valid packet changed is caught by the CRC-8 (a burst of at most 8
        /// bits): a corrupted byte never decodes.
        #[test]
        fn one_corrupted_byte_is_caught(c in any_commands(), r in any_reply(), at in 0usize..36, x in 1u8..=255) {
            let mut b = c.encode();
            b[at] ^= x;
            let caught = matches!(MotorCommands::decode(&b), Err(PacketError::Checksum { .. }));
            prop_assert!(caught, "command byte {} ^ {}", at, x);
            let mut b = r.encode();
            b[at % REPLY_SIZE] ^= x;
            let caught = matches!(SlaveReply::decode(&b), Err(PacketError::Checksum { .. }));
            prop_assert!(caught, "reply byte {} ^ {}", at % REPLY_SIZE, x);
        }

        /// Whatever a decoder accepts encodes back to the same bytes.
        #[test]
        fn accepted_bytes_are_canonical(bytes in proptest::collection::vec(any::<u8>(), 0..48)) {
            if let Ok(c) = MotorCommands::decode(&bytes) {
                prop_assert_eq!(&c.encode()[..], &bytes[..]);
            }
            if let Ok(r) = SlaveReply::decode(&bytes) {
                prop_assert_eq!(&r.encode()[..], &bytes[..]);
            }
        }
    }

    /// The fuzz target of the link: 10^6 arbitrary datagrams (any size 0..64, then packets with
    /// their CRC fixed so that the version and range checks are reached too) through both
    /// parsers, with no panic; every rejection is counted under one kind.
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
            for result in [MotorCommands::decode(bytes).map(|_| ()), SlaveReply::decode(bytes).map(|_| ())] {
                inputs += 1;
                match result {
                    Ok(()) => accepted += 1,
                    Err(e) => counts.count(&e),
                }
            }
        }
        assert_eq!(inputs, 2_000_000);
        assert_eq!(counts.total() + accepted, inputs);
        // Every check was exercised.
        assert!(counts.size > 0 && counts.checksum > 0 && counts.version > 0 && counts.range > 0 && accepted > 0, "{counts:?}, {accepted} accepted");
    }

    /// The command CRC is linear: an error pattern goes undetected iff the XOR of the
    /// syndromes of its bits is 0. Every corrupted byte (255 patterns at each of the 36
    /// positions) and every error of 1, 2 or 3 bits has a non-zero syndrome.
    #[test]
    fn command_crc_catches_every_byte_and_three_bit_error() {
        let clean = MotorCommands::zero(0).encode();
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
        // Seq 0x1234, version 1: header 34 12 01 crc 00..; duty +5 on motor 0, -1023 on motor 17.
        let mut duties = [Duty::ZERO; JOINTS];
        duties[0] = Duty(5);
        duties[17] = Duty(-1023);
        let b = MotorCommands { seq: 0x1234, duties }.encode();
        assert_eq!(u16::from_le_bytes([b[0], b[1]]), 0x4005); // nibble 0 = 4 (seq low nibble), duty 5
        assert_eq!(u16::from_le_bytes([b[2], b[3]]) >> 12, 0x3);
        assert_eq!(u16::from_le_bytes([b[4], b[5]]) >> 12, 0x2);
        assert_eq!(u16::from_le_bytes([b[6], b[7]]) >> 12, 0x1);
        assert_eq!(u16::from_le_bytes([b[8], b[9]]) >> 12, 0x1); // version 1, low nibble
        assert_eq!(u16::from_le_bytes([b[34], b[35]]), 0x07FF); // direction + 1023
        let r = SlaveReply { leg: 3, seq: 0x1234, counts: [-1, 0x123456, 0], currents_ma: [-2, 0, 25_000], supply: 120 }.encode();
        assert_eq!(&r[..12], &[0x13, 0x34, 0x12, 0xFF, 0xFF, 0xFF, 0x56, 0x34, 0x12, 0, 0, 0]);
        assert_eq!(&r[12..19], &[0xFE, 0xFF, 0, 0, 0xA8, 0x61, 120]);
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
        let r = SlaveReply::measured(7, 9, [1 << 30, -5, 0], [0.0015, f64::NAN, -99.0], 12.04);
        assert_eq!((r.leg, r.counts, r.currents_ma, r.supply), (1, [COUNT_MAX, -5, 0], [2, 0, -25_000], 120));
        assert_eq!(r.supply_voltage(), 12.0);
    }

    #[test]
    fn rejections_name_their_cause() {
        assert_eq!(SlaveReply::decode(&[0; 19]), Err(PacketError::Size { expected: 20, got: 19 }));
        let mut b = SlaveReply { leg: 0, seq: 1, counts: [0; 3], currents_ma: [0; 3], supply: 120 }.encode();
        b[0] = 0x26; // version 2, leg 6
        b[19] = CRC8.checksum(&b[..19]);
        assert_eq!(SlaveReply::decode(&b), Err(PacketError::Version(2)));
        b[0] = 0x16;
        b[19] = CRC8.checksum(&b[..19]);
        assert!(matches!(SlaveReply::decode(&b), Err(PacketError::OutOfRange { field: "leg", value: 6, .. })));
        assert_eq!(seq_distance(2, 65534), 4);
        assert_eq!(seq_distance(65534, 2), -4);
    }
}
