/* LD_PRELOAD shim for the serial-BLAS test (issue #26): every pthread_create
 * fails with EAGAIN, as under an exhausted thread limit. A threaded OpenBLAS
 * makes its threads in its constructor, before main, and the process dies of
 * it; with the serial OpenBLAS (RCB_SERIAL_BLAS) rcbtool runs. */
#include <errno.h>
#include <pthread.h>

int pthread_create(pthread_t *t, const pthread_attr_t *attr, void *(*fn)(void *), void *arg);

int pthread_create(pthread_t *t, const pthread_attr_t *attr, void *(*fn)(void *), void *arg) {
  (void)t;
  (void)attr;
  (void)fn;
  (void)arg;
  return EAGAIN;
}
