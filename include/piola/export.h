/* piola: symbol visibility. Everything is hidden unless marked PIOLA_API. */
#ifndef PIOLA_EXPORT_H
#define PIOLA_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_API __attribute__((visibility("default")))
#else
#define PIOLA_API
#endif

#endif
