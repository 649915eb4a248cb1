/**
 * @file rcb_export.h
 * @brief RCB_API: symbol visibility. The shared library is built with hidden
 * visibility by default, so only functions marked RCB_API are exported.
 */
#ifndef RCB_EXPORT_H
#define RCB_EXPORT_H

#if defined(_WIN32) && !defined(RCB_STATIC)
#if defined(RCB_BUILDING)
#define RCB_API __declspec(dllexport)
#else
#define RCB_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#define RCB_API __attribute__((visibility("default")))
#else
#define RCB_API
#endif

#endif /* RCB_EXPORT_H */
