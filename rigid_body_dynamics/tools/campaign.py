"""
rigid_body_campaign: run a Monte Carlo campaign from its file; judge and tabulate it.

    rigid_body_campaign CONFIG.yaml [--workers N | --scheduler tcp://HOST:PORT]
                                    [--runs N] [--output DIR]

Runs the runs that have no record yet (a killed campaign started again goes on
where it stopped), then writes runs.csv, ensemble.csv and report.html into the
campaign's folder and prints the ensemble's verdict. Exit status 0 when every
run flew, 1 when some failed (their errors are in runs.csv), 2 for a file or
option that is refused (one line saying why).
"""

import argparse
import os
import sys

from ..campaign import gather, judge, load, run_campaign, summary_lines, write
from ..optional import MissingDependency
from ..ros.parameters import ConfigurationError


def main(argv=None):
    """Run the command line; return the exit status."""
    parser = argparse.ArgumentParser(prog='rigid_body_campaign', description=__doc__.split(
        '\n\n')[0].strip())
    parser.add_argument('config', help='the campaign file (YAML)')
    where = parser.add_mutually_exclusive_group()
    where.add_argument('--workers', type=int, default=None,
                       help='local worker processes (default: one per core; 0: in this '
                            'process, without Dask)')
    where.add_argument('--scheduler', help="a Dask scheduler's address, tcp://HOST:PORT")
    parser.add_argument('--runs', type=int, help="the number of runs (instead of the file's)")
    parser.add_argument('--output', help="the results' folder (default: the file's key, or "
                                         'beside the file)')
    args = parser.parse_args(argv)
    if args.workers is not None and args.workers < 0:
        parser.error('--workers must be >= 0')
    try:
        campaign = load(args.config)
        if args.output:
            campaign.output = os.path.abspath(args.output)
        if args.runs is not None:
            if args.runs < 2:
                raise ConfigurationError(f'--runs must be >= 2, got {args.runs}')
            campaign.values['runs'] = args.runs
        run_campaign(campaign, workers=args.workers, scheduler=args.scheduler)
        ens = gather(campaign.output)
        judgement = judge(campaign, ens)
    except (ConfigurationError, MissingDependency, ValueError) as err:
        print(f'rigid_body_campaign: {err}', file=sys.stderr)
        return 2
    runs_csv, ensemble_csv, page = write(campaign, ens, judgement)
    for line in summary_lines(campaign, ens, judgement):
        print(line)
    print(f'  tables: {runs_csv}, {ensemble_csv}' + (f'; page: {page}' if page else ''))
    return 1 if ens.failed else 0


if __name__ == '__main__':
    sys.exit(main())
