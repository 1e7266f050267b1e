// Test-bed self-test: a program that UndefinedBehaviorSanitizer reports on
// and that still exits 0 (UBSan recovers by default), so only the bed's own
// rule can fail the test that runs it: a sanitizer's report fails its test.
#include <limits.h>
#include <stdio.h>

int main(void)
{
	volatile int largest = INT_MAX;
	int overflowed = largest + 1;

	printf("computed %d and exited 0\n", overflowed);
	return 0;
}
