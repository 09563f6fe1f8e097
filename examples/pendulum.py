"""A pendulum of length 1 m released horizontally: its period against the exact period.

The exact period of a simple pendulum released at rest from angle a is 4 sqrt(L/g) K(sin(a/2)),
K the complete elliptic integral of the first kind: 2.367841947576237 s for L = 1 m, g = 9.81,
a = 90 degrees.

    python examples/pendulum.py [--dt 1e-3] [--plot pendulum.png]
"""

import argparse

from vinculo import demos


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dt", type=float, default=1e-3, help="step size in s (default 1e-3)")
    parser.add_argument("--plot", metavar="FILE", help="write a PNG plot to FILE")
    args = parser.parse_args()

    result = demos.run_pendulum(periods=3, dt=args.dt)
    print(f"period: {result.period:.10f} s")
    print(f"exact:  {result.exact_period:.10f} s")
    print(f"relative error: {result.relative_error:.2e}")
    if args.plot:
        from vinculo.plotting import plot_pendulum

        print(f"plot: {plot_pendulum(result, args.plot)}")


if __name__ == "__main__":
    main()
