#!/usr/bin/python3
# SPDX-License-Identifier: ISC
"""A Modbus TCP server (pymodbus) emulating an ADAM-6024-style 0-10 V I/O
module with a lux meter, for testing psensd's Modbus driver against a peer
we did not write.

  mbserver.py PORT READY_FILE [TABLE:ADDR=VALUE ...]

TABLE is hr (holding registers), ir (input registers), co (coils) or di
(discrete inputs); ADDR is 0-based.  200 registers and bits per table; an
address beyond them answers exception 2 (illegal data address).  The ready
file gets the port once the server accepts connections."""
import asyncio
import sys

from pymodbus.datastore import (ModbusSequentialDataBlock, ModbusServerContext,
                                ModbusSlaveContext)
from pymodbus.server.async_io import ModbusTcpServer


def main():
    port, ready = int(sys.argv[1]), sys.argv[2]
    tables = {t: [0] * 200 for t in ("hr", "ir", "co", "di")}
    for item in sys.argv[3:]:
        where, value = item.split("=")
        table, addr = where.split(":")
        tables[table][int(addr)] = int(value, 0)
    store = ModbusSlaveContext(
        di=ModbusSequentialDataBlock(0, tables["di"]),
        co=ModbusSequentialDataBlock(0, tables["co"]),
        hr=ModbusSequentialDataBlock(0, tables["hr"]),
        ir=ModbusSequentialDataBlock(0, tables["ir"]),
        zero_mode=True)
    context = ModbusServerContext(slaves=store, single=True)

    async def run():
        server = ModbusTcpServer(context, address=("127.0.0.1", port),
                                 allow_reuse_address=True)
        task = asyncio.ensure_future(server.serve_forever())
        await server.serving
        with open(ready + ".tmp", "w") as f:
            f.write(f"{port}\n")
        import os
        os.rename(ready + ".tmp", ready)
        await task

    asyncio.run(run())


if __name__ == "__main__":
    main()
