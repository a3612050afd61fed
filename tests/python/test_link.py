"""The robot link from Python: the packet mirror against the engine, and `hexadyn robot
emulate` + `hexadyn robot run` over the loopback interface (127.0.0.0/8 only)."""

from __future__ import annotations

import random
import re
import socket
import subprocess
import sys

import pytest
from click.testing import CliRunner

from hexadyn import Results, _core, health
from hexadyn.cli import cli
from hexadyn.link import LOOPBACK
from hexadyn.options import UNHEALTHY
from hexadyn.link.packets import COMMAND_SIZE, REPLY_SIZE, SERVO_VERSION, MotorCommands, PacketError, ServoCommands, SlaveReply, crc8_autosar, crc16_ibm3740

from conftest import shortened


def random_command(rng: random.Random) -> MotorCommands:
    return MotorCommands(rng.randrange(1 << 16), tuple(rng.randint(-1023, 1023) for _ in range(18)), rng.randrange(1 << 32))


def random_reply(rng: random.Random) -> SlaveReply:
    return SlaveReply(
        rng.randrange(6),
        rng.randrange(1 << 16),
        tuple(rng.randint(-(1 << 23), (1 << 23) - 1) for _ in range(3)),
        tuple(rng.randint(-25000, 25000) for _ in range(3)),
        rng.randrange(256),
    )


def documented_dump(text: str) -> bytes:
    return bytes.fromhex(text.replace("\n", " "))


#: The bytes of a command packet whose high nibbles hold its CRC-16 (docs/protocol.md).
CRC_BYTES = (13, 15, 17, 19)


def command_crc(data: bytes) -> int:
    """The CRC-16 of a command packet as docs/protocol.md defines it: over the packet with its
    own nibbles as 0."""
    return crc16_ibm3740(bytes(b & 0x0F if i in CRC_BYTES else b for i, b in enumerate(data)))


def stored_crc(data: bytes) -> int:
    """The CRC-16 a command packet carries in its nibbles."""
    return sum((data[i] >> 4) << (4 * k) for k, i in enumerate(CRC_BYTES))


def test_the_packets_are_docs_protocol_examples_and_round_trip():
    assert crc8_autosar(b"123456789") == 0xDF and crc16_ibm3740(b"123456789") == 0x29B1
    # docs/protocol.md, "Examples": the command and the slave packet answering it.
    duties = (5,) + (0,) * 16 + (-1023,)
    command = documented_dump("05 40 00 30 00 20 00 10 00 30 00 00 00 10 00 00 00 10 00 00\n00 f0 00 e0 00 d0 00 c0 00 b0 00 a0 00 90 ff 87")
    assert MotorCommands(0x1234, duties, 0x89ABCDEF).encode() == command and MotorCommands.decode(command) == MotorCommands(0x1234, duties, 0x89ABCDEF)
    reply = documented_dump("33 34 12 ff ff ff 56 34 12 00 00 00 fe ff 00 00 a8 61 78 15")
    assert SlaveReply(3, 0x1234, (-1, 0x123456, 0), (-2, 0, 25000), 120).encode() == reply
    rng = random.Random(12)
    for _ in range(2000):
        c = random_command(rng)
        data = c.encode()
        assert len(data) == COMMAND_SIZE and MotorCommands.decode(data) == c
        assert command_crc(data) == stored_crc(data)
        r = random_reply(rng)
        data = r.encode()
        assert len(data) == REPLY_SIZE and SlaveReply.decode(data) == r and crc8_autosar(data[:-1]) == data[-1]


def test_servo_packets_are_not_motor_packets():
    rng = random.Random(7)
    for _ in range(3000):
        c = ServoCommands(rng.randrange(1 << 16), tuple(rng.randrange(1 << 12) for _ in range(18)), rng.randrange(1 << 32))
        data = c.encode()
        assert ServoCommands.decode(data) == c
        with pytest.raises(PacketError, match="protocol version 4, this side speaks 3") as e:
            MotorCommands.decode(data)
        assert e.value.kind == "version"
        r = SlaveReply(rng.randrange(6), rng.randrange(1 << 16), tuple(rng.randrange(2048) for _ in range(3)), tuple(rng.randint(-25000, 25000) for _ in range(3)), rng.randrange(256))
        data = r.encode(SERVO_VERSION)
        assert SlaveReply.decode(data, SERVO_VERSION) == r and crc8_autosar(data[:-1]) == data[-1]
        with pytest.raises(PacketError) as e:
            SlaveReply.decode(data)
        assert e.value.kind == "version"
    # A forged servo packet: a position beyond 11 bits, with a valid CRC.
    data = bytearray(SlaveReply(0, 1, (0, 0, 0), (0, 0, 0), 111).encode(SERVO_VERSION))
    data[3:6] = (4096).to_bytes(3, "little")
    data[-1] = crc8_autosar(bytes(data[:-1]))
    with pytest.raises(PacketError, match="position count = 4096 out of range") as e:
        SlaveReply.decode(bytes(data), SERVO_VERSION)
    assert e.value.kind == "range"
    assert ServoCommands.goal(512) == 0xA00


def test_every_rejected_datagram_is_a_packet_error_of_its_kind():
    rng = random.Random(5)
    kinds = {"size": "bytes, expected", "checksum": "corrupted", "version": "protocol version", "range": "out of range"}
    seen = set()
    for n in range(4000):
        good = random_reply(rng).encode() if n % 2 else random_command(rng).encode()
        data = bytearray(good)
        if n % 5 == 0:
            data = data[: rng.randrange(len(data))]
        else:
            data[rng.randrange(len(data))] ^= rng.randrange(1, 256)
        with pytest.raises(PacketError) as error:
            (SlaveReply.decode if n % 2 else MotorCommands.decode)(bytes(data))
        assert kinds[error.value.kind] in str(error.value)
        seen.add(error.value.kind)
    assert seen == {"size", "checksum"}
    # A command with the reserved bit 11 set, its CRC made valid again.
    data = bytearray(MotorCommands(1, (0,) * 18).encode())
    data[1] |= 0x08
    crc = command_crc(data)
    for k, i in enumerate(CRC_BYTES):
        data[i] = (data[i] & 0x0F) | ((crc >> (4 * k)) & 0x0F) << 4
    assert command_crc(data) == stored_crc(data)
    with pytest.raises(PacketError, match="bit 11 \\(reserved\\)") as error:
        MotorCommands.decode(bytes(data))
    assert error.value.kind == "range"


def free_udp_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("name, joint", [("stand_six_legs", "q_v"), ("phantomx_stand", "femur")])
def test_robot_run_on_the_emulated_slaves_in_lock_step(tmp_path, name, joint):
    # The master and the six emulated slaves in one process, on a virtual clock: the packets
    # cross the loopback interface, but no period can be missed or late because of the
    # scheduler, so the shipped configuration (3 missing periods, no overrun tolerance) holds.
    scenario = shortened(name, tmp_path, 1.0)
    out = tmp_path / "robot"
    result = CliRunner().invoke(cli, ["robot", "run", str(scenario), "--link", "loopback", "--emulated", "--out", str(out), "--no-progress", "--no-plots"])
    assert result.exit_code == 0, result.output
    results = Results.load(out)
    ts = results.timeseries
    assert results.summary["missed_periods"] == 0 and results.summary["safety_stop"] == "none"
    assert len(ts) == 101 and ts.index[-1] == pytest.approx(1.0)
    # Virtual time: every broadcast on its deadline, the last slave packet at t_s0 + 5 dt_s.
    assert results.units["lateness"] == "s" and (ts["lateness"] == 0).all()
    assert (ts["last_reply"] - 0.005).abs().max() < 1e-12
    # Standing: the PI loops hold the joints within a few encoder counts of their references; the
    # AX-12A servos within 2 degrees (their compliance law under the body's weight: 1 degree).
    tolerance = 1e-4 if joint == "q_v" else 0.035
    assert (ts[f"{joint}[0]"] - ts[f"{joint}_ref[0]"]).abs().max() < tolerance
    assert (out / "power.csv").is_file() and (out / "energy.csv").is_file()
    raw = _core.robot_run(str(scenario), str(LOOPBACK), emulated=True)
    assert raw["emulator"]["commands"] == 102 and raw["emulator"]["error"] is None  # the start, 100 updates, the stop


def test_robot_run_checks_its_health_and_strict_exits_3(tmp_path, monkeypatch):
    """The health checks of `hexadyn simulate` (`hexadyn.health.check`) on the summary of what
    the master saw: kept in summary.json (`warnings`), printed as WARNING lines, and --strict
    makes a failed one exit status 3. The master's summary has none of the model's figures the
    checks read (energy balance, penetration, body pose), so a failed check is stood in for."""
    scenario = shortened("stand_six_legs", tmp_path, 0.5)
    args = ["robot", "run", str(scenario), "--link", "loopback", "--emulated", "--no-progress", "--no-plots"]
    healthy = CliRunner().invoke(cli, [*args, "--strict", "--out", str(tmp_path / "healthy")])
    assert healthy.exit_code == 0 and "WARNING" not in healthy.output, healthy.output
    assert Results.load(tmp_path / "healthy").summary["warnings"] == []
    seen = []
    monkeypatch.setattr(health, "check", lambda summary: seen.append(summary["control_periods"]) or ["the limit switches cut a motor 1 times"])
    for strict, status in [([], 0), (["--strict"], UNHEALTHY)]:
        out = tmp_path / f"unhealthy{len(strict)}"
        result = CliRunner().invoke(cli, [*args, *strict, "--out", str(out)])
        assert result.exit_code == status, result.output
        assert result.stderr == "WARNING: the limit switches cut a motor 1 times\n", result.stderr
        assert Results.load(out).summary["warnings"] == ["the limit switches cut a motor 1 times"]
    assert seen == [50, 50]


def test_robot_emulate_answers_each_command_with_six_packets(tmp_path):
    # `hexadyn robot emulate` in its own process on the monotonic clock: each new command gets
    # the six packets of its sequence number (the deadline is the test's: none but liveness).
    scenario = shortened("stand_six_legs", tmp_path, 1.0)
    port = free_udp_port()
    link = tmp_path / "link.toml"
    link.write_text(LOOPBACK.read_text().replace("127.255.255.255:47101", f"127.255.255.255:{port}"))
    emulator = subprocess.Popen(
        [sys.executable, "-c", "from hexadyn.cli import main; main()", "robot", "emulate", str(scenario), "--link", str(link), "--idle-timeout", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as master:
            master.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
            master.bind(("127.0.0.1", 0))
            master.settimeout(0.2)
            legs: dict[int, set[int]] = {}
            for seq in range(600):  # the emulator settles its robot first: at most 2 minutes
                master.sendto(MotorCommands(seq, (0,) * 18).encode(), ("127.255.255.255", port))
                try:
                    while True:
                        reply = SlaveReply.decode(master.recv(64))
                        legs.setdefault(reply.seq, set()).add(reply.leg)
                except TimeoutError:
                    pass
                if any(len(v) == 6 for v in legs.values()):
                    break
        stdout, stderr = emulator.communicate(timeout=60)
    finally:
        emulator.kill()
    assert any(v == set(range(6)) for v in legs.values()), legs
    assert emulator.returncode == 0, stderr
    assert re.search(r"Emulator: \d+ commands applied", stdout), stdout


def test_robot_run_errors_are_one_line(tmp_path):
    result = CliRunner().invoke(cli, ["robot", "run", "stand_six_legs", "--link", str(tmp_path / "missing.toml")])
    assert result.exit_code == 1 and "missing.toml" in result.output
    bad = tmp_path / "bad.toml"
    bad.write_text(LOOPBACK.read_text().replace("period_s = 0.01", "period_s = 0.02"))
    result = CliRunner().invoke(cli, ["robot", "run", "stand_six_legs", "--link", str(bad), "--no-progress"])
    assert result.exit_code == 1 and "timing.period_s" in result.output, result.output


@pytest.mark.parametrize("rehearsal, reason", [(["--silent-slave", "3:40"], "missing_replies"), (["--stall-at", "0.5:60"], "master_overrun")])
def test_every_safety_stop_leaves_its_results_and_reason(tmp_path, rehearsal, reason):
    # A slave that falls silent, a master that freezes for 60 ms: rehearsed on the emulated slaves
    # in lock-step; the run ends with one line naming the stop, exit status 1, and the rows up
    # to the stop are saved with the reason in the summary.
    scenario = shortened("stand_six_legs", tmp_path, 1.0)
    out = tmp_path / "robot"
    result = CliRunner().invoke(cli, ["robot", "run", str(scenario), "--link", "loopback", "--emulated", "--out", str(out), "--no-progress", "--no-plots", *rehearsal])
    assert result.exit_code == 1, result.output
    error = result.output.strip().splitlines()[-1]
    assert error.startswith("Error: safety stop at period") and "Traceback" not in result.output, result.output
    results = Results.load(out)
    assert results.summary["safety_stop_reason"] == reason
    assert results.summary["safety_stop"] == error.removeprefix("Error: ")
    assert 10 < len(results.timeseries) < 101  # the rows up to the stop


def test_an_interrupt_is_a_stop_with_its_reason(tmp_path):
    scenario = shortened("stand_six_legs", tmp_path, 600.0)

    def interrupt(t: float, duration: float) -> None:
        raise KeyboardInterrupt

    raw = _core.robot_run(str(scenario), str(LOOPBACK), interrupt, emulated=True)
    assert raw["stop"].endswith("on request; every motor set to 0 V")
    assert raw["summary"]["safety_stop_reason"] == "interrupted"


def test_faults_are_rehearsed_on_the_emulated_slaves_only():
    result = CliRunner().invoke(cli, ["robot", "run", "stand_six_legs", "--link", "loopback", "--no-progress", "--silent-slave", "3:40"])
    assert result.exit_code == 1 and result.output.strip() == "Error: --silent-slave: faults are rehearsed on the emulated slaves only; allowed with --emulated", result.output


def test_a_safety_stop_at_the_first_instant_saves_its_results_and_reason(tmp_path):
    """Found by test_fuzz_cli.py: a rehearsal whose slaves lose half their packets stops at
    period 3 with a single recorded instant; its average power was 0/0 (ZeroDivisionError) and
    its power table had no period to average over. The folder is saved with the stop's reason,
    the analyses that need a period are skipped with a note, and the command ends in one line."""
    scenario = shortened("stand_six_legs", tmp_path, 0.03)
    out = tmp_path / "out"
    result = CliRunner().invoke(cli, ["robot", "run", str(scenario), "--link", "loopback", "--emulated", "--loss", "0.5", "--no-progress", "--out", str(out)])
    assert result.exit_code == 1 and result.exception is not None and isinstance(result.exception, SystemExit), result.output
    assert result.stderr.splitlines() == ["Error: safety stop at period 3: no packet from the slave(s) of leg(s) [1] for 3 periods, the master on time; every motor set to 0 V"]
    saved = Results.load(out)
    assert saved.shape[0] == 1 and saved.summary["safety_stop_reason"] == "missing_replies"
    assert saved.summary["analysis_skipped"] == "power.csv and the figures: the time series has a single instant: no control period to average powers over"
    assert not (out / "power.csv").exists() and not (out / "plots").exists()


@pytest.mark.parametrize("command", ["emulate", "run"])
def test_a_negative_fault_seed_is_a_usage_error(command):
    """Found by test_fuzz_cli.py: `--seed -1` reached the engine's unsigned seed: an
    OverflowError traceback."""
    result = CliRunner().invoke(cli, ["robot", command, "stand_six_legs", "--link", "loopback", "--seed", "-1"])
    assert result.exit_code == 2 and result.exception is not None and isinstance(result.exception, SystemExit)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: Invalid value for '--seed': -1 is not in the range 0<=x<=18446744073709551615"), lines
