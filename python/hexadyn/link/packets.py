"""The link packets from Python (thesis Section 2.3.2; layout in ``docs/protocol.md``): typed
values over the engine's codec (``_core.encode_command``, ``decode_command``,
``encode_reply``, ``decode_reply``; the layout is defined once, in ``link/protocol.rs``, whose
tests hold it to the byte dumps of docs/protocol.md), which decode with the engine's checks in
the engine's order: size, CRC, version, ranges. For tools and tests: sniffing, replaying,
writing a test slave; :func:`crc8_autosar` and :func:`crc16_ibm3740` forge packets.

- Command packet, 36 bytes: 18 little-endian 16-bit words, word k for motor k = 3 leg + (0:
  q_r, 1: q_v, 2: q_h): bits 0-9 PWM duty, bit 10 direction (1: negative), bit 11 reserved
  (0), bits 12-15 nibble k of the 9-byte header (sequence number u16, version 3, CRC-16 u16,
  the master's run number u32). CRC-16/IBM-3740 over the 36 bytes with its own nibbles (words
  6-9) as 0.
- Slave packet, 20 bytes: version << 4 | leg; sequence number u16; three signed 24-bit encoder
  counts; three i16 currents (mA); supply u8 (0.1 V); CRC-8/AUTOSAR of bytes 0-18.
- Servo variant, protocol version 4 (position servos): command word bits 0-10 a goal register
  (0..2047), bit 11 the torque enable; the slave packet's 24-bit fields the present positions
  (0..2047), its currents the servos' present currents.
"""

from __future__ import annotations

import binascii
from dataclasses import dataclass
from typing import Any, Callable

from hexadyn import _core

PROTOCOL_VERSION = 3
#: Protocol version of the servo variant.
SERVO_VERSION = 4
GOAL_MAX = 0x07FF
COMMAND_SIZE = 36
REPLY_SIZE = 20
JOINTS = 18
DUTY_MAX = 1023
CURRENT_MAX_MA = 25_000
COUNT_MIN = -(1 << 23)
COUNT_MAX = (1 << 23) - 1
#: Supply voltage of one least significant bit (V).
SUPPLY_LSB_V = 0.1

_TORQUE_BIT = 1 << 11

__all__ = ["PacketError", "MotorCommands", "ServoCommands", "SlaveReply", "SERVO_VERSION", "crc8_autosar", "crc16_ibm3740", "COMMAND_SIZE", "REPLY_SIZE", "PROTOCOL_VERSION"]


def _crc8_table() -> list[int]:
    """CRC-8/AUTOSAR's table (poly 0x2F, not reflected): the standard library has no CRC-8."""
    table = []
    for byte in range(256):
        c = byte
        for _ in range(8):
            c = ((c << 1) ^ 0x2F) & 0xFF if c & 0x80 else (c << 1) & 0xFF
        table.append(c)
    return table


_CRC8 = _crc8_table()


def crc8_autosar(data: bytes) -> int:
    """CRC-8/AUTOSAR: poly 0x2F, init 0xFF, xorout 0xFF, not reflected (check 0xDF)."""
    c = 0xFF
    for b in data:
        c = _CRC8[c ^ b]
    return c ^ 0xFF


def crc16_ibm3740(data: bytes) -> int:
    """CRC-16/IBM-3740 (CCITT-FALSE): poly 0x1021, init 0xFFFF, xorout 0, not reflected (check
    0x29B1); the standard library's ``binascii.crc_hqx`` started at 0xFFFF."""
    return binascii.crc_hqx(data, 0xFFFF)


class PacketError(ValueError):
    """A datagram that is not a valid packet; ``kind`` is size, checksum, version or range."""

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


#: What the engine's rejection of a datagram says, by kind (``PacketError`` of link/protocol.rs).
_KINDS = (("size", " bytes, expected "), ("checksum", "): corrupted"), ("version", ", this side speaks "), ("range", " out of range; allowed: "))


def _decoded(decode: Callable[[bytes, int], Any], data: bytes, version: int) -> Any:
    """`decode` (an engine decoder) of `data`; its rejection as a :class:`PacketError`."""
    try:
        return decode(bytes(data), version)
    except ValueError as exc:
        message = str(exc)
        kind = next((k for k, said in _KINDS if said in message), None)
        if kind is None:
            raise
        raise PacketError(kind, message) from None


def _check_header(seq: int, run: int) -> None:
    """The header's fields in their ranges (the engine takes them as u16 and u32)."""
    if not 0 <= seq <= 0xFFFF or not 0 <= run <= 0xFFFF_FFFF:
        raise ValueError(f"seq = {seq}, run = {run}: allowed 0..65535 and 0..4294967295")


@dataclass(frozen=True)
class MotorCommands:
    """A command packet: the period's sequence number, the 18 signed duties (-1023..1023) and the
    master's run number (the slaves follow the run of their handshake, docs/protocol.md)."""

    seq: int
    duties: tuple[int, ...]
    run: int = 0

    def encode(self) -> bytes:
        _check_header(self.seq, self.run)
        return _core.encode_command(self.seq, list(self.duties), PROTOCOL_VERSION, self.run)

    @classmethod
    def decode(cls, data: bytes) -> "MotorCommands":
        seq, run, duties = _decoded(_core.decode_command, data, PROTOCOL_VERSION)
        return cls(seq, tuple(duties), run)


@dataclass(frozen=True)
class ServoCommands:
    """A servo command packet (version 4): the sequence number, 18 servo words, bits 0-10 the
    goal register (0..2047), bit 11 the torque enable (0: torque off, the goal ignored), and the
    master's run number."""

    seq: int
    words: tuple[int, ...]
    run: int = 0

    @staticmethod
    def goal(register: int) -> int:
        """The word holding `register` (0..2047) with the torque on."""
        if not 0 <= register <= GOAL_MAX:
            raise ValueError(f"goal register {register}: allowed 0..2047")
        return register | _TORQUE_BIT

    def encode(self) -> bytes:
        _check_header(self.seq, self.run)
        return _core.encode_command(self.seq, list(self.words), SERVO_VERSION, self.run)

    @classmethod
    def decode(cls, data: bytes) -> "ServoCommands":
        seq, run, words = _decoded(_core.decode_command, data, SERVO_VERSION)
        return cls(seq, tuple(words), run)


@dataclass(frozen=True)
class SlaveReply:
    """A slave packet: leg 0..5, the sequence number it answers, the encoder counts of q_r, q_v,
    q_h (500 per motor revolution), the motor currents (mA) and the supply (units of 0.1 V)."""

    leg: int
    seq: int
    counts: tuple[int, int, int]
    currents_ma: tuple[int, int, int]
    supply: int

    @property
    def supply_voltage(self) -> float:
        """Supply voltage (V), exactly as the engine computes it (supply / 10)."""
        return self.supply / 10.0

    def encode(self, version: int = PROTOCOL_VERSION) -> bytes:
        """The packet of `version` (3: encoder counts; 4: servo positions 0..2047); ValueError
        for a field out of its range (the engine's encoder saturates them, as a board does)."""
        low, high = _count_range(version)
        if not 0 <= self.leg < 6 or not 0 <= self.seq <= 0xFFFF or not 0 <= self.supply <= 255:
            raise ValueError(f"leg = {self.leg}, seq = {self.seq}, supply = {self.supply}: allowed 0..5, 0..65535, 0..255")
        if any(not low <= c <= high for c in self.counts) or any(abs(i) > CURRENT_MAX_MA for i in self.currents_ma):
            raise ValueError(f"counts = {self.counts}, currents = {self.currents_ma} mA: allowed counts {low}..{high}, |i| <= 25000 mA")
        return _core.encode_reply(self.leg, self.seq, list(self.counts), list(self.currents_ma), self.supply, version)

    @classmethod
    def decode(cls, data: bytes, version: int = PROTOCOL_VERSION) -> "SlaveReply":
        leg, seq, counts, currents, supply = _decoded(_core.decode_reply, data, version)
        return cls(leg, seq, tuple(counts), tuple(currents), supply)


def _count_range(version: int) -> tuple[int, int]:
    """The range of a slave packet's position counts in `version`."""
    if version == PROTOCOL_VERSION:
        return COUNT_MIN, COUNT_MAX
    if version == SERVO_VERSION:
        return 0, GOAL_MAX
    raise ValueError(f"protocol version {version}: allowed 3 (motor duties) or 4 (servo goals)")
