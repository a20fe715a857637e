/* SPDX-License-Identifier: Apache-2.0 */
/* icoac_version(): the release version the library was built as (icoac_version.h, generated). */
#include "icoac/icoac.h"
#include "icoac/icoac_version.h"

const char *icoac_version(void) { return ICOAC_VERSION_STRING; }
