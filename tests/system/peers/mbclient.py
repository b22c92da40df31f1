#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""A Modbus client (pymodbus) reading psvirt the way a site's tools would.

  mbclient.py tcp HOST PORT COMMAND...      mbclient.py rtu DEVICE COMMAND...
  COMMAND: [unit=N] hr ADDR COUNT | ir ADDR COUNT | write ADDR VALUE |
           u32 ADDR | f32 ADDR [cdab] | status07 | time ADDR N [GAP]

Prints the values one per line, or "exception N" for an exception reply and
"error TEXT" when there is no usable reply (exit 1).  status07 is function
07 (read exception status).  time reads holding register ADDR N times on one
connection, GAP seconds apart (0.02) as a poller does, and prints the
latency of the reads as "reads N errors N median_ms X p90_ms X max_ms X"."""
import struct
import sys
import time

from pymodbus.client import ModbusSerialClient, ModbusTcpClient


def timed(client, addr, n, unit, gap):
    """n reads, each timed on the monotonic clock; errors (timeouts,
    exceptions) count and are timed too."""
    ms, errors = [], 0
    for i in range(n):
        if i:
            time.sleep(gap)
        t0 = time.monotonic()
        try:
            rr = client.read_holding_registers(addr, 1, slave=unit)
            bad = rr.isError()
        except Exception:  # pylint: disable=broad-except
            bad = True
        ms.append((time.monotonic() - t0) * 1000)
        if bad:
            errors += 1
            client.close()
            client.connect()
    client.close()
    ms.sort()
    print(f"reads {n} errors {errors} median_ms {ms[n // 2]:.1f} "
          f"p90_ms {ms[(n * 9) // 10]:.1f} max_ms {ms[-1]:.1f}")
    return 0


def main():
    args = sys.argv[1:]
    if args[0] == "tcp":
        client = ModbusTcpClient(args[1], port=int(args[2]), timeout=1, retries=0)
        args = args[3:]
    else:
        client = ModbusSerialClient(port=args[1], baudrate=9600, timeout=1, retries=0)
        args = args[2:]
    if not client.connect():
        print("error cannot connect")
        return 1
    unit = 1
    if args[0].startswith("unit="):
        unit = int(args[0][5:])
        args = args[1:]
    cmd = args[0]
    addr = int(args[1]) if len(args) > 1 else 0
    if cmd == "time":
        return timed(client, addr, int(args[2]), unit, float(args[3]) if len(args) > 3 else 0.02)
    try:
        if cmd == "write":
            rr = client.write_register(addr, int(args[2]), slave=unit)
        elif cmd == "ir":
            rr = client.read_input_registers(addr, int(args[2]), slave=unit)
        elif cmd == "status07":
            rr = client.read_exception_status(slave=unit)
        else:
            rr = client.read_holding_registers(addr, int(args[2]) if cmd == "hr" else 2, slave=unit)
    except Exception as exc:  # pylint: disable=broad-except
        print(f"error {exc}")
        return 1
    finally:
        client.close()
    if rr.isError():
        code = getattr(rr, "exception_code", None)
        print(f"exception {code}" if code is not None else f"error {rr}")
        return 1
    if cmd == "write":
        print("written")
    elif cmd == "status07":
        print(rr.status)
    elif cmd in ("hr", "ir"):
        for v in rr.registers:
            print(v)
    elif cmd == "u32":
        print((rr.registers[0] << 16) | rr.registers[1])
    else:
        hi, lo = rr.registers if len(args) < 3 else reversed(rr.registers)
        print(repr(struct.unpack(">f", struct.pack(">HH", hi, lo))[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
