/* host_sizes.c -- not run: compiled for the host, its arrays' sizes (read back with nm -S by tools/build/sizes.sh) are the host's structs' sizeof, for docs/sizes.md; no code. */
#define _DEFAULT_SOURCE
#include "app.h"
#include "control.h"
#include "link.h"
#include "mav.h"
#include "obsmap.h"
#include "options.h"
#include "sinks.h"
#include "source_coproc.h"
#include "source_link.h"
#include "survey_run.h"

/* One array per struct: sizeof_<header>__<struct>. */
#define SIZE(h, s) unsigned char sizeof_##h##__##s[sizeof(struct s)];
SIZE(app, app_storage)
SIZE(options, sonard_options)
SIZE(link, link)
SIZE(mav, mav)
SIZE(obsmap, obsmap)
SIZE(source_link, source_link)
SIZE(source_coproc, source_coproc)
SIZE(sinks, sink_lcm)
SIZE(sinks, sink_csv)
SIZE(sinks, sink_report)
SIZE(survey_run, survey_run)
SIZE(control, control)
