"""What the source checks of tests/format share: the files of the tree and
the command line (REPO_ROOT, or --self-test)."""
import subprocess
import sys


def tree_files(root, patterns=()):
    """The tracked files (and untracked ones git does not ignore) matching
    `patterns` (all when none), relative to `root`."""
    return subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard", *patterns], cwd=root,
                          capture_output=True, text=True, check=True).stdout.splitlines()


def run(doc, main, self_test):
    """Exits with self_test() for --self-test, main(REPO_ROOT) for a root,
    else prints `doc` and exits 2."""
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    if len(sys.argv) != 2:
        print(doc)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
