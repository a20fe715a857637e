# SPDX-License-Identifier: Apache-2.0
from icoac.cli import main

raise SystemExit(main())
