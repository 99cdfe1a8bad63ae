/* version.h -- sonard's version, the one place it is written (sonard --version, the Debian package's name); no RAM. */
#ifndef SONARD_VERSION_H
#define SONARD_VERSION_H

#define SONARD_VERSION "0.4.0"

#endif
