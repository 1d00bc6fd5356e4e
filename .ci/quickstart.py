"""Print the README's two quick-start commands, one per line (CI runs exactly these)."""
import pathlib
import re
import sys

text = pathlib.Path(__file__).resolve().parent.parent.joinpath("README.md").read_text()
section = text.split("## Quick start", 1)[1].split("\n## ", 1)[0]
commands = re.findall(r"```bash\n(.+?)\n```", section, flags=re.S)
if len(commands) != 2 or any("\n" in c for c in commands):
    sys.exit("README quick start must hold exactly two one-line bash blocks")
print("\n".join(commands))
