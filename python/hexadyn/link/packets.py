"""Python mirror of the link packets (thesis Section 2.3.2; layout in ``docs/protocol.md``).

It encodes byte for byte what the engine encodes (``hexadyn.link.protocol`` in Rust; the test
suite compares both on random packets) and decodes with the same checks in the same order:
size, CRC, version, ranges. For tools and tests: sniffing, replaying, writing a test slave.

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

import struct
from dataclasses import dataclass

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

_DIRECTION_BIT = 1 << 10
_RESERVED_BIT = 1 << 11
_TORQUE_BIT = 1 << 11
_HEADER_BYTES = JOINTS // 2
_HEADER_SEQ, _HEADER_VERSION, _HEADER_CRC, _HEADER_RUN = 0, 2, 3, 5
_CRC_WORDS = (6, 7, 8, 9)

__all__ = ["PacketError", "MotorCommands", "ServoCommands", "SlaveReply", "SERVO_VERSION", "crc8_autosar", "crc16_ibm3740", "COMMAND_SIZE", "REPLY_SIZE", "PROTOCOL_VERSION"]


def _crc_table(poly: int, width: int) -> list[int]:
    top, mask = 1 << (width - 1), (1 << width) - 1
    table = []
    for byte in range(256):
        c = byte << (width - 8)
        for _ in range(8):
            c = ((c << 1) ^ poly) & mask if c & top else (c << 1) & mask
        table.append(c)
    return table


_CRC8 = _crc_table(0x2F, 8)
_CRC16 = _crc_table(0x1021, 16)


def crc8_autosar(data: bytes) -> int:
    """CRC-8/AUTOSAR: poly 0x2F, init 0xFF, xorout 0xFF, not reflected (check 0xDF)."""
    c = 0xFF
    for b in data:
        c = _CRC8[c ^ b]
    return c ^ 0xFF


def crc16_ibm3740(data: bytes) -> int:
    """CRC-16/IBM-3740 (CCITT): poly 0x1021, init 0xFFFF, xorout 0, not reflected (check 0x29B1)."""
    c = 0xFFFF
    for b in data:
        c = ((c << 8) & 0xFFFF) ^ _CRC16[(c >> 8) ^ b]
    return c


class PacketError(ValueError):
    """A datagram that is not a valid packet; ``kind`` is size, checksum, version or range."""

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


def _command_crc(data: bytes) -> int:
    b = bytearray(data)
    for w in _CRC_WORDS:
        b[2 * w + 1] &= 0x0F
    return crc16_ibm3740(bytes(b))


def _encode_command(seq: int, run: int, bits: list[int], version: int) -> bytes:
    """The command packet of `version` with the 12 setpoint bits of each word."""
    header = bytearray(_HEADER_BYTES)
    header[_HEADER_SEQ : _HEADER_SEQ + 2] = seq.to_bytes(2, "little")
    header[_HEADER_VERSION] = version
    header[_HEADER_RUN:] = run.to_bytes(4, "little")
    words = [b | ((header[k // 2] >> (4 * (k % 2))) & 0x0F) << 12 for k, b in enumerate(bits)]
    data = bytearray(struct.pack("<18H", *words))
    crc = _command_crc(bytes(data))
    for i, w in enumerate(_CRC_WORDS):
        data[2 * w + 1] = (data[2 * w + 1] & 0x0F) | ((crc >> (4 * i)) & 0x0F) << 4
    return bytes(data)


def _decode_command(data: bytes, version: int) -> tuple[int, int, tuple[int, ...]]:
    """(seq, run, the 18 words) of a command packet of `version`, checked as the engine checks it."""
    if len(data) != COMMAND_SIZE:
        raise PacketError("size", f"{len(data)} bytes, expected {COMMAND_SIZE}")
    words = struct.unpack("<18H", data)
    header = bytearray(_HEADER_BYTES)
    for k, w in enumerate(words):
        header[k // 2] |= (w >> 12) << (4 * (k % 2))
    computed = _command_crc(data)
    received = int.from_bytes(header[_HEADER_CRC : _HEADER_CRC + 2], "little")
    if computed != received:
        raise PacketError("checksum", f"CRC {received:#06x} does not match the content ({computed:#06x}): corrupted")
    if header[_HEADER_VERSION] != version:
        raise PacketError("version", f"protocol version {header[_HEADER_VERSION]}, this side speaks {version}")
    return int.from_bytes(header[_HEADER_SEQ : _HEADER_SEQ + 2], "little"), int.from_bytes(header[_HEADER_RUN:], "little"), words


def _check_header(seq: int, run: int) -> None:
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
        if len(self.duties) != JOINTS or any(abs(d) > DUTY_MAX for d in self.duties):
            raise ValueError(f"duties = {self.duties}: allowed 18 integers in -1023..1023")
        return _encode_command(self.seq, self.run, [abs(d) | (_DIRECTION_BIT if d < 0 else 0) for d in self.duties], PROTOCOL_VERSION)

    @classmethod
    def decode(cls, data: bytes) -> "MotorCommands":
        seq, run, words = _decode_command(data, PROTOCOL_VERSION)
        if any(w & _RESERVED_BIT for w in words):
            raise PacketError("range", "command word bit 11 (reserved) is set")
        duties = tuple(-(w & DUTY_MAX) if w & _DIRECTION_BIT else w & DUTY_MAX for w in words)
        return cls(seq, duties, run)


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
        if len(self.words) != JOINTS or any(not 0 <= w <= 0x0FFF for w in self.words):
            raise ValueError(f"words = {self.words}: allowed 18 integers in 0..4095")
        return _encode_command(self.seq, self.run, list(self.words), SERVO_VERSION)

    @classmethod
    def decode(cls, data: bytes) -> "ServoCommands":
        seq, run, words = _decode_command(data, SERVO_VERSION)
        return cls(seq, tuple(w & 0x0FFF for w in words), run)


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
        """The packet of `version` (3: encoder counts; 4: servo positions 0..2047)."""
        low, high = _count_range(version)
        if not 0 <= self.leg < 6 or not 0 <= self.seq <= 0xFFFF or not 0 <= self.supply <= 255:
            raise ValueError(f"leg = {self.leg}, seq = {self.seq}, supply = {self.supply}: allowed 0..5, 0..65535, 0..255")
        if any(not low <= c <= high for c in self.counts) or any(abs(i) > CURRENT_MAX_MA for i in self.currents_ma):
            raise ValueError(f"counts = {self.counts}, currents = {self.currents_ma} mA: allowed counts {low}..{high}, |i| <= 25000 mA")
        data = bytearray([version << 4 | self.leg]) + self.seq.to_bytes(2, "little")
        for c in self.counts:
            data += (c & 0xFFFFFF).to_bytes(3, "little")
        data += struct.pack("<3hB", *self.currents_ma, self.supply)
        data.append(crc8_autosar(bytes(data)))
        return bytes(data)

    @classmethod
    def decode(cls, data: bytes, version: int = PROTOCOL_VERSION) -> "SlaveReply":
        low, high = _count_range(version)
        if len(data) != REPLY_SIZE:
            raise PacketError("size", f"{len(data)} bytes, expected {REPLY_SIZE}")
        computed = crc8_autosar(data[:-1])
        if computed != data[-1]:
            raise PacketError("checksum", f"CRC {data[-1]:#06x} does not match the content ({computed:#06x}): corrupted")
        leg = data[0] & 0x0F
        if data[0] >> 4 != version:
            raise PacketError("version", f"protocol version {data[0] >> 4}, this side speaks {version}")
        if leg >= 6:
            raise PacketError("range", f"leg = {leg} out of range; allowed: 0..5")
        counts = tuple(int.from_bytes(data[3 + 3 * j : 6 + 3 * j], "little", signed=True) for j in range(3))
        if any(not low <= c <= high for c in counts):
            raise PacketError("range", f"position count = {counts} out of range; allowed: {low}..{high}")
        *currents, supply = struct.unpack("<3hB", data[12:19])
        if any(abs(i) > CURRENT_MAX_MA for i in currents):
            raise PacketError("range", f"motor current (mA) = {currents} out of range; allowed: -25000..25000")
        return cls(leg, int.from_bytes(data[1:3], "little"), counts, tuple(currents), supply)


def _count_range(version: int) -> tuple[int, int]:
    """The range of a slave packet's position counts in `version`."""
    if version == PROTOCOL_VERSION:
        return COUNT_MIN, COUNT_MAX
    if version == SERVO_VERSION:
        return 0, GOAL_MAX
    raise ValueError(f"protocol version {version}: allowed 3 (motor duties) or 4 (servo goals)")
