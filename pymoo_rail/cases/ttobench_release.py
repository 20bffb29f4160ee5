"""Which TTOBench train suits which TTOBench track, for runs on the whole public release.

TTOBench pairs no train with its tracks. :data:`SUITABLE_TRAINS` is our choice, by country and top
speed: the Dutch intercity (140 km/h) on the 48.5 km reference family (140 km/h limits), the Stadler
trains on the Swiss lines (the FLIRT of the Fribourg operator TPF on Fribourg-Bern, the SBB KISS on
the Zurich and St. Gallen lines), the SBB KISS (160 km/h) on the Swedish line (no Swedish train is
in the library), and the Beijing subway train on the Yizhuang line.
"""

from __future__ import annotations

from pathlib import Path

SUITABLE_TRAINS = {
    "00_reference": "NL_Intercity_VIRM6",
    "00_reference_with_tunnels": "NL_Intercity_VIRM6",
    "00_var_gradient_minus_10": "NL_Intercity_VIRM6",
    "00_var_gradient_minus_5": "NL_Intercity_VIRM6",
    "00_var_gradient_minusplus_6": "NL_Intercity_VIRM6",
    "00_var_gradient_plus_10": "NL_Intercity_VIRM6",
    "00_var_gradient_plus_5": "NL_Intercity_VIRM6",
    "00_var_speed_limit_100": "NL_Intercity_VIRM6",
    "00_var_speed_limit_110": "NL_Intercity_VIRM6",
    "00_var_speed_limit_120": "NL_Intercity_VIRM6",
    "00_var_speed_limit_wind": "NL_Intercity_VIRM6",
    "CH_Fribourg_Bern": "CH_Stadler_FLIRT_TPF",
    "CH_Stadelhofen_Altstetten": "CH_Stadler_KISS_SBB",
    "CH_StGallen_Wil": "CH_Stadler_KISS_SBB",
    "CN_Songjiazhuang_Yizhuang": "CN_Beijing_Subway",
    "SE_Vasteras_Kolback": "CH_Stadler_KISS_SBB",
}


def release_pairs(root: str | Path) -> list[tuple[Path, Path]]:
    """``(track file, train file)`` for every track of a TTOBench checkout at ``root``.

    ``root`` holds ``tracks/`` and ``trains/``; a track not in :data:`SUITABLE_TRAINS` is an error
    (a new release needs a decision, not a silent default).
    """
    root = Path(root)
    pairs = []
    for track in sorted((root / "tracks").glob("*.json")):
        if track.stem not in SUITABLE_TRAINS:
            raise KeyError(f"{track}: no suitable train chosen for track {track.stem!r} (add it to SUITABLE_TRAINS)")
        pairs.append((track, root / "trains" / f"{SUITABLE_TRAINS[track.stem]}.json"))
    return pairs
