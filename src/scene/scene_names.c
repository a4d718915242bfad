/* src/scene/scene_names.c — what a name may be: identifiers and reserved words.
 * SPDX-License-Identifier: MIT */
#include <ctype.h>
#include <string.h>

#include "scene/scene_internal.h"

/* A name is a letter or '_' followed by letters, digits or '_' (the expression grammar's
 * names; a prime is not part of a name). */
int sc_is_identifier(const char *s)
{
  if (!(isalpha((unsigned char)s[0]) || s[0] == '_'))
    return 0;
  for (const char *p = s + 1; *p; p++)
    if (!(isalnum((unsigned char)*p) || *p == '_'))
      return 0;
  return 1;
}

/* Names a scene may not define: the constant pi, the function names (a parameter called
 * `exp` would be shadowed by exp( ... ) or shadow it) and `free`, which [boundary] reads
 * as a natural end. */
int sc_is_reserved(const char *s)
{
  static const char *const words[] = {
    "pi", "free", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh",
    "asinh", "acosh", "atanh", "exp", "log", "sqrt", "abs", "atan2", "pow", "min", "max",
    "if"};
  for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
    if (strcmp(s, words[i]) == 0)
      return 1;
  return 0;
}
