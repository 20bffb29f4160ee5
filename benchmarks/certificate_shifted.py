"""The certificate against ms-eetc N=2000 at shifted running times, and its CPU (``pymoo_rail.experiments.certificate_check``).

Usage (resumable: ms-eetc's answers are cached in the CSV)::

    nice -n 10 python benchmarks/certificate_shifted.py --fill --mseetc /path/to/ms-eetc --cache runs/mseetc_shifted.csv
    nice -n 10 python benchmarks/certificate_shifted.py --cache benchmarks/reports/certificate_shifted_mseetc_N2000.csv
    nice -n 10 python benchmarks/certificate_shifted.py --benchmark-times --cache benchmarks/reports/peers_mseetc_N2000.csv
    nice -n 10 python benchmarks/certificate_shifted.py --cpu --seeds 6
"""

from pymoo_rail.experiments.certificate_check import main

if __name__ == "__main__":
    main()
