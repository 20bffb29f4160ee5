"""OSRD's realistic fleet on an OSRD line: the fastest run against the energy-optimal one.

OSRD (railjson) ships 11 realistic rolling stocks in its test data and computes the mechanical
energy of a run, but does no optimisation. This script loads each (``pymoo_rail.cases.load_train``),
runs it on 26.3 km of OSRD's ``small_infra`` (Mid_East_station -> West_station: +-6 permille
stretches, a 1500 V-only end, a neutral section) and on a generated line of its kind
(``generate_case(0, kind)``, from rest to rest), and prints for each the flat-out running time and
mechanical energy, and the minimum energy at 15 % more running time
(``pymoo_rail.optimal.optimal_profile``), every run checked (``check_run``).

Usage: ``python benchmarks/osrd_fleet.py`` (about half a minute) from the repository root.
"""

from __future__ import annotations

from pathlib import Path

from pymoo_rail.experiments.osrd_fleet import fleet_lines

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "osrd"


def main() -> None:
    print("| train | mass t | OSRD line: min time s | flat-out kWh | optimal kWh (+15 % time) | saving "
          "| generated line (kind, km) | min time s | flat-out kWh | optimal kWh | saving |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for line in fleet_lines(DATA):
        print(line, flush=True)


if __name__ == "__main__":
    main()
