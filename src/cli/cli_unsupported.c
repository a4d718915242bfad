/* src/cli/cli_unsupported.c — commands of SCENES.md that this build does not provide yet
 * (converge): say so and exit 2, never pretend.
 * SPDX-License-Identifier: MIT */
#include <stdio.h>

#include "cli/cli.h"

int cli_unsupported(const char *cmd)
{
  fprintf(stderr, "calcvar %s: not supported by this build yet\n", cmd);
  return EXIT_BADINPUT;
}
