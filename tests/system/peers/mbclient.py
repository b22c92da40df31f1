#!/usr/bin/python3
"""A Modbus client (pymodbus) reading psvirt the way a site's tools would.

  mbclient.py tcp HOST PORT COMMAND...      mbclient.py rtu DEVICE COMMAND...
  COMMAND: hr ADDR COUNT | ir ADDR COUNT | write ADDR VALUE | u32 ADDR |
           f32 ADDR [cdab]

Prints the values one per line, or "exception N" for an exception reply and
"error TEXT" when there is no usable reply (exit 1)."""
import struct
import sys

from pymodbus.client import ModbusSerialClient, ModbusTcpClient


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
    cmd, addr = args[0], int(args[1])
    try:
        if cmd == "write":
            rr = client.write_register(addr, int(args[2]), slave=1)
        elif cmd == "ir":
            rr = client.read_input_registers(addr, int(args[2]), slave=1)
        else:
            rr = client.read_holding_registers(addr, int(args[2]) if cmd == "hr" else 2, slave=1)
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
