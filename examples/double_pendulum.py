"""A small-amplitude double pendulum (equal masses, equal 1 m rods): its normal-mode frequencies.

Linearised theory gives omega^2 = (2 -/+ sqrt 2) g / l. The rod angles are projected onto the two
normal modes and each modal coordinate's frequency is measured from its zero crossings.

    python examples/double_pendulum.py [--plot double_pendulum.png]
"""

import argparse

from vinculo import demos


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=20.0, help="duration in s (default 20)")
    parser.add_argument("--plot", metavar="FILE", help="write a PNG plot to FILE")
    args = parser.parse_args()

    result = demos.run_double_pendulum(t_end=args.t_end)
    for name, measured, exact in zip(
        ("slow", "fast"), result.frequencies, result.exact_frequencies, strict=True
    ):
        print(f"{name} mode: omega = {measured:.8f} rad/s (exact {exact:.8f} rad/s)")
    if args.plot:
        from vinculo.plotting import plot_double_pendulum

        print(f"plot: {plot_double_pendulum(result, args.plot)}")


if __name__ == "__main__":
    main()
