/* config_doc.c -- writes docs/configuration.md: the template with @OPTIONS@ replaced by the option table's Markdown (options.c); a few KB of stdio. */
#include <stdio.h>
#include <string.h>

#include "options.h"

int main(int argc, char **argv)
{
    char line[4096];
    FILE *in;
    if (argc != 2) {
        fprintf(stderr, "usage: config_doc TEMPLATE.md.in > OUT.md\n");
        return 2;
    }
    if ((in = fopen(argv[1], "r")) == NULL) {
        perror(argv[1]);
        return 2;
    }
    while (fgets(line, sizeof(line), in) != NULL) {
        if (strcmp(line, "@OPTIONS@\n") == 0)
            options_markdown(stdout);
        else
            fputs(line, stdout);
    }
    fclose(in);
    return ferror(stdout) ? 1 : 0;
}
