"""A particle sliding on a frictionless 30 degree plane: acceleration and normal force.

Down the slope the particle accelerates at g sin(theta); the plane pushes with m g cos(theta),
which is the constraint's multiplier times |n|.

    python examples/inclined_plane.py [--angle 30] [--plot inclined_plane.png]
"""

import argparse

import numpy as np

from vinculo import demos


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--angle", type=float, default=30.0, help="inclination in degrees")
    parser.add_argument("--plot", metavar="FILE", help="write a PNG plot to FILE")
    args = parser.parse_args()

    model = demos.build_inclined_plane(angle=np.radians(args.angle))
    result = demos.run_inclined_plane(model=model)
    print(
        f"acceleration: {result.acceleration:.10f} m/s^2 "
        f"(exact g sin th = {result.exact_acceleration:.10f})"
    )
    print(
        f"normal force: {np.mean(result.normal_force):.10f} N "
        f"(exact m g cos th = {result.exact_normal_force:.10f})"
    )
    if args.plot:
        from vinculo.plotting import plot_inclined_plane

        print(f"plot: {plot_inclined_plane(result, args.plot)}")


if __name__ == "__main__":
    main()
