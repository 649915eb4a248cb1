/* rcbtool monitor --state FILE: the commissioning image beside the state
 * (FILE.image, issue #34 item 5). A run per measurement re-created the
 * monitor from the state's set-up and settings, about 0.5 s of sweeps and
 * QRs; the image (rcb_monitor_image_save) holds their results, so a run that
 * finds one creates the monitor in a tenth of that, with the same results
 * bit for bit. The image is the library's bytes as they are: the library
 * checks them all (a checksum, a fingerprint of the model's values on the
 * set-up, the set-up, the settings and the candidates, every dimension and
 * value). One that is missing, damaged, of another version or of other
 * inputs (a changed model file) is not an error: the monitor is created in
 * full and the image written again. It is an output of the run's plan
 * (read, then rewritten: CLI_IO_INOUT, locked with the state), written to a
 * temporary and renamed with the other outputs when the run succeeds. */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cmd_monitor.h"

/* The mode a plain fopen would have given (0666 & ~umask), as the state's. */
static void plain_mode(FILE *fp) {
  mode_t mask = umask(0);
  umask(mask);
  (void)fchmod(fileno(fp), (mode_t)(0666 & ~mask));
}

char *mon_image_path(const char *state) {
  char *p = malloc(strlen(state) + sizeof ".image");
  if (p) strcat(strcpy(p, state), ".image");
  return p;
}

/* The file's bytes (NULL when it cannot be read: none yet). */
int mon_image_read(const char *path, void **buf, size_t *n) {
  FILE *fp = fopen(path, "rb");
  long len;
  *buf = NULL, *n = 0;
  if (!fp) return 0;
  if (fseek(fp, 0, SEEK_END) == 0 && (len = ftell(fp)) > 0 && fseek(fp, 0, SEEK_SET) == 0 &&
      (*buf = malloc((size_t)len)) != NULL && fread(*buf, 1, (size_t)len, fp) == (size_t)len) {
    *n = (size_t)len;
  } else {
    free(*buf);
    *buf = NULL;
  }
  fclose(fp);
  return *buf != NULL;
}

int mon_image_write(const char *cmd, const char *path, const rcb_monitor *mon, cli_tmpfile *t) {
  size_t n = rcb_monitor_image_size(mon);
  unsigned char *b = malloc(n ? n : 1);
  FILE *fp;
  int rc, bad;
  if (!b || rcb_monitor_image_save(mon, b, n, NULL)) {
    free(b);
    return cli_fail(CLI_EXIT_NUMERIC, "%s: out of memory (commissioning image)", cmd);
  }
  if ((rc = cli_tmpfile_open(t, path))) {
    free(b);
    return rc;
  }
  if (!(fp = fopen(t->write_path, "wb"))) {
    free(b);
    cli_tmpfile_close(t, 0);
    return cli_fail(CLI_EXIT_IO, "%s: cannot write the commissioning image '%s'", cmd, path);
  }
  plain_mode(fp);
  bad = fwrite(b, 1, n, fp) != n;
  if (fclose(fp) != 0) bad = 1;
  free(b);
  if (bad) {
    cli_tmpfile_close(t, 0);
    return cli_fail(CLI_EXIT_IO, "%s: cannot write the commissioning image '%s'", cmd, path);
  }
  return 0; /* renamed by the caller with the other outputs */
}
