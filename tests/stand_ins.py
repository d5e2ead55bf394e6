"""Small stand-ins for the expensive inputs of the pipeline and report tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from softbend.design import DesignSpace


def small_space() -> DesignSpace:
    """Two levels of l, t and b: enough for the regression, fast enough for CI (8 designs)."""
    return DesignSpace.grid(
        {
            "l_mm": [100.0, 130.0],
            "r_mm": [6.0],
            "t_mm": [2.0, 3.0],
            "b_mm": [2.0, 3.0],
            "phi_deg": [5.0],
            "lc_mm": [8.0],
        },
        name="small",
    )


def stand_in_fem_dataset(folder: Path) -> Path:
    """A small dataset in the shipped format (analytical sweeps of 15 designs: fast, same table)."""
    from softbend.campaign import run_campaign
    from softbend.dataset_writing import write_dataset

    db = folder / "stand_in.duckdb"
    run_campaign(db, DesignSpace.sample(15, seed=4), backend="analytical", workers=0)
    write_dataset(db, folder / "dataset", command="stand-in for the test")
    return folder / "dataset"


def web_server():
    """A local TCP server answering every connection like a web server; returns (port, close)."""
    import socket
    import threading

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    server.settimeout(0.1)
    stop = threading.Event()

    def serve() -> None:
        while not stop.is_set():
            try:
                conn, _ = server.accept()
            except OSError:
                continue
            with conn:
                conn.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()

    def close() -> None:
        stop.set()
        thread.join()
        server.close()

    return server.getsockname()[1], close


class StuckOpen:
    """A controller that keeps the inlet open: only a watchdog can vent after the link goes."""

    predicted_deg = float("nan")

    def reset(self):
        pass

    def step(self, measurement_mpa, reference_deg, t_s):
        return (True, False)


# --- an actuator other than paper B's: a simulation table by named columns -----------------

ACTUATOR_COLUMNS = "n_chambers,wall_mm,height_mm,layer"


def actuator_law(n, wall, height, layer, p_kpa):
    """A made-up bending law of a four-parameter actuator, degrees (pre-curved by -3°)."""
    stiffness = wall * (1.3 if layer == "fabric" else 1.0)
    return -3.0 + n * height * (p_kpa / 50.0) ** 1.2 / stiffness


def actuator_table(designs: int = 24, seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(designs):
        n = int(rng.integers(6, 15))
        wall = round(float(rng.uniform(1.0, 3.0)), 1)
        height = round(float(rng.uniform(8.0, 16.0)), 1)
        layer = str(rng.choice(["paper", "fabric"]))
        for p in np.linspace(0.0, 50.0, 6):
            rows.append(
                {
                    "design_id": f"d{i:02d}",
                    "n_chambers": n,
                    "wall_mm": wall,
                    "height_mm": height,
                    "layer": layer,
                    "p_kpa": p,
                    "angle_deg": actuator_law(n, wall, height, layer, p),
                }
            )
    return pd.DataFrame(rows)
